#include "ddemap/io/svg.hpp"

#include "core/internal/text.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

namespace ddemap {

namespace {

// class 4 (peak stable) only where the sweep decided the peak notion; class 3 is then the points
// that are L2 string stable but whose step response overshoots (||h||_1 > 1)
const char* region_fill[5] = {"#d73027", "#fc8d59", "#fee090", "#91bfdb", "#4575b4"};
const char* region_name[5] = {"plant unstable", "ring unstable", "string unstable", "string stable", "string stable (L2 and peak)"};
const char* kRegionL2Only = "string stable (L2), peak unstable (overshoot)";

/// Text for an SVG (XML 1.0) element or attribute: the five markup characters as entities, and
/// what XML cannot hold (control characters but tab and line ends, bytes that are not UTF-8) as
/// U+FFFD.
std::string esc(const std::string& text) {
    const std::string s = detail::utf8_replaced(text);
    std::string o;
    for (char c : s) {
        const auto u = static_cast<unsigned char>(c);
        switch (c) {
            case '&': o += "&amp;"; break;
            case '<': o += "&lt;"; break;
            case '>': o += "&gt;"; break;
            case '"': o += "&quot;"; break;
            case '\'': o += "&#39;"; break;
            default:
                if ((u < 0x20 && c != '\t' && c != '\n' && c != '\r') || u == 0x7f) o += "\xEF\xBF\xBD";
                else o += c;
        }
    }
    return o;
}

std::string num(double v) {
    if (!std::isfinite(v)) throw std::logic_error("a non-finite number (" + std::to_string(v) + ") reached an SVG coordinate");
    char b[32];
    std::snprintf(b, sizeof b, "%.2f", v);
    return b;
}

std::string tick_text(double v, double step) {
    char b[32];
    const int decimals = std::max(0, static_cast<int>(std::ceil(-std::log10(step) - 1e-9)));
    std::snprintf(b, sizeof b, "%.*f", decimals, std::abs(v) < 1e-12 * step ? 0.0 : v);
    return b;
}

/// The multiples of `step` in [lo, hi] (to 1e-9 steps), by integer index so that a step below the
/// spacing of doubles near lo cannot loop forever; empty when there would be more than 1000.
std::vector<double> tick_values(double lo, double hi, double step) {
    std::vector<double> ticks;
    if (!(step > 0) || !std::isfinite(lo) || !std::isfinite(hi)) return ticks;
    const double first = std::ceil(lo / step - 1e-9), last = std::floor(hi / step + 1e-9);
    if (!(last - first < 1000)) return ticks;
    for (double i = first; i <= last; ++i) ticks.push_back(i * step);
    return ticks;
}

double nice_step(double range) {
    const double raw = range / 5.0;
    const double p = std::pow(10.0, std::floor(std::log10(raw)));
    const double m = raw / p;
    return (m < 1.5 ? 1.0 : m < 3.5 ? 2.0 : m < 7.5 ? 5.0 : 10.0) * p;
}

/// XML declaration, the svg element (width x height px), a white background and the title.
void svg_preamble(std::ostringstream& s, double width, double height, const std::string& title, double title_size = 15) {
    s << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
    s << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << num(width) << "\" height=\"" << num(height)
      << "\" viewBox=\"0 0 " << num(width) << " " << num(height) << "\" font-family=\"DejaVu Sans, Helvetica, Arial, sans-serif\">\n";
    s << "<rect id=\"background\" x=\"0\" y=\"0\" width=\"" << num(width) << "\" height=\"" << num(height) << "\" fill=\"#ffffff\"/>\n";
    if (!title.empty()) {
        s << "<text id=\"title\" x=\"" << num(width / 2) << "\" y=\"22\" text-anchor=\"middle\" font-size=\"" << num(title_size) << "\" font-weight=\"bold\">"
          << esc(title) << "</text>\n";
    }
}

struct Style {
    const char* colour;
    const char* dash;
    double width;
    const char* name;
};

Style curve_style(BoundaryKind k) {
    switch (k) {
        case BoundaryKind::PlantHopf: return {"#67001f", "", 2.2, "plant Hopf boundary"};
        case BoundaryKind::RingHopf: return {"#000000", "", 1.2, "ring Hopf boundary (mode crossing)"};
        case BoundaryKind::LowFrequency: return {"#08519c", "6,3", 1.8, "string boundary, low frequency (c\u2082 = 0)"};
        case BoundaryKind::Peak: return {"#6a3d9a", "2,2", 1.8, "string boundary, peak of |\u0393(i\u03c9)| = 1"};
    }
    return {"#000", "", 1.0, ""};
}

}  // namespace

int region_class(const SweepPoint& p) {
    if (!p.plant_stable) return 0;
    if (!p.ring_stable) return 1;
    if (!p.string_stable) return 2;
    if (p.has_peak && p.peak_stable) return 4;
    return 3;
}

std::string parameter_symbol(const std::string& name) {
    static const std::pair<const char*, const char*> symbols[] = {
        {"k1", "k\u2081"}, {"k2", "k\u2082"}, {"k3", "k\u2083"}, {"tau", "\u03c4"}, {"tau2", "\u03c4\u2082"},
        {"th", "t\u2095"}, {"eta", "\u03b7"}, {"alpha", "\u03b1"}, {"beta", "\u03b2"}, {"delta", "\u03b4"}};
    for (const auto& [n, sym] : symbols)
        if (name == n) return sym;
    return name;
}

std::string unit_text(const std::string& unit) {
    std::string u = unit;
    for (const auto& [from, to] : {std::pair<std::string, std::string>{"^2", "\u00b2"}, {"^3", "\u00b3"}, {"^-1", "\u207b\u00b9"}}) {
        for (std::size_t at = u.find(from); at != std::string::npos; at = u.find(from)) u.replace(at, from.size(), to);
    }
    return u;
}

std::string axis_label(const std::string& model, const std::string& parameter) {
    for (const auto& s : model_parameters(model))
        if (s.name == parameter) return parameter_symbol(parameter) + (s.unit == "1" ? std::string(" [1]") : " [" + unit_text(s.unit) + "]");
    return parameter_symbol(parameter);
}

namespace {

/// Approximate advance of `text` in px at `size` px in DejaVu Sans (0.62 em a character;
/// multi-byte UTF-8 sequences count once).
double text_width(const std::string& text, double size) {
    std::size_t chars = 0;
    for (unsigned char c : text) chars += (c & 0xC0) != 0x80 ? 1 : 0;
    return 0.62 * size * static_cast<double>(chars);
}

/// The largest font size <= `size` (and >= `min_size`) at which `text` fits `width`.
double fitted_size(const std::string& text, double size, double width, double min_size) {
    const double w = text_width(text, size);
    return w <= width ? size : std::max(min_size, size * width / w);
}

/// Margin whose sign decides the region boundary crossed between two grid points, for the
/// condition that fails at `out` (region_class(out) = 0 plant, 1 ring, 2 string): positive
/// where the condition holds.
double condition_margin(const SweepPoint& p, int condition, bool lowfreq) {
    switch (condition) {
        case 0: return -p.plant_abscissa;
        case 1: return -p.spectral_abscissa;
        case 2: return lowfreq ? p.lowfreq_margin : 1.0 - p.peak_gain;
        default: return 1.0 - p.peak_norm;  // 3: L2 stable, the peak condition ||h||_1 <= 1
    }
}

}  // namespace

std::string render_chart_svg(const std::vector<ChartPanel>& panels, const ChartOptions& o) {
    if (panels.empty()) throw std::invalid_argument("a chart needs at least one panel");
    for (const auto& p : panels)
        if (p.sweep == nullptr) throw std::invalid_argument("a chart panel needs a sweep");
    const int cols = std::max(1, std::min<int>(o.columns, static_cast<int>(panels.size())));
    const int rows = (static_cast<int>(panels.size()) + cols - 1) / cols;
    // type sizes [px]: readable when the figure is set at a journal's text width (a 1100 px wide
    // figure at 174 mm puts 13 px at 5.8 pt, 14 px at 6.2 pt)
    const double f_tick = 13, f_label = 14, f_title = 14, f_legend = 14, f_head = 17;
    const double ml = 70, mr = 18, mt = 46, mb = 54;  // margins around each plot area (two title lines fit above)
    const double cw = o.panel_width + ml + mr, ch = o.panel_height + mt + mb;
    // the figure is as wide as its panels, or wider where the title (at 12 px or more) or a legend
    // item needs it: nothing is cut off, whatever the names
    double width = cols * cw + 10;
    width = std::max(width, text_width(o.title, 12) + 20);

    // what the figure shows: region classes (grid points), boundary kinds, markers, ellipses
    bool class_shown[5] = {false, false, false, false, false};
    bool any_peak = false;  // some panel decided the peak notion: class 3 is then "L2 only"
    bool kind_shown[4] = {false, false, false, false};
    bool any_marker = false, any_ellipse = false, any_outside = false, any_cut = false;
    const BoundaryKind kinds[4] = {BoundaryKind::RingHopf, BoundaryKind::PlantHopf, BoundaryKind::LowFrequency, BoundaryKind::Peak};
    for (const auto& panel : panels) {
        for (const auto& pt : panel.sweep->points) {
            class_shown[region_class(pt)] = true;
            any_peak = any_peak || pt.has_peak;
        }
        if (panel.boundaries)
            for (const auto& c : panel.boundaries->curves)
                for (int k = 0; k < 4; ++k) kind_shown[k] = kind_shown[k] || (c.kind == kinds[k] && c.points.size() >= 2);
        const Axis& ax = panel.sweep->spec.x;
        const Axis& ay = panel.sweep->spec.y;
        for (const auto& m : panel.markers) {
            any_marker = true;
            any_ellipse = any_ellipse || m.has_ellipse;
            if (m.has_ellipse) {  // the ellipse's extent along each axis: sqrt(5.991 C_ii)
                const double ex = std::sqrt(5.991464547107979 * std::max(0.0, m.cov_xx)), ey = std::sqrt(5.991464547107979 * std::max(0.0, m.cov_yy));
                any_cut = any_cut || m.x - ex < ax.lo || m.x + ex > ax.hi || m.y - ey < ay.lo || m.y + ey > ay.hi;
            }
            any_outside = any_outside || !(m.x >= ax.lo && m.x <= ax.hi && m.y >= ay.lo && m.y <= ay.hi);
        }
    }
    // legend items, wrapped to the figure width
    struct Item {
        int type;  // 0 swatch, 1 line, 2 marker, 3 ellipse, 4 outside marker, 5 path
        int index;
        std::string text;
    };
    std::vector<Item> items;
    for (int c = 4; c >= 0; --c)
        if (class_shown[c]) items.push_back({0, c, c == 3 && any_peak ? kRegionL2Only : region_name[c]});
    for (int k = 0; k < 4; ++k)
        if (kind_shown[k]) items.push_back({1, k, curve_style(kinds[k]).name});
    if (any_marker) items.push_back({2, 0, "marked setting (k\u2081, k\u2082)"});
    if (any_ellipse)
        items.push_back({3, 0, any_cut ? "95 % confidence ellipse of (k\u2081, k\u2082), cut where it leaves the window"
                                       : "95 % confidence ellipse of (k\u2081, k\u2082)"});
    if (any_outside) items.push_back({4, 0, "outside the window (at its edge)"});
    bool any_path = false;
    for (const auto& panel : panels) any_path = any_path || panel.path.size() >= 2;
    if (any_path) items.push_back({5, 0, "the minimiser's path (its iterates)"});
    for (const auto& it : items) width = std::max(width, 36 + text_width(it.text, f_legend) + 20);
    // marker labels: the names beside the markers where every panel's names fit (at most 45 % of
    // the plot width each) and no two labels, or a label and another marker, overlap; otherwise
    // numbers (one per distinct name in the figure), with a key under the legend
    std::vector<std::string> names;  // distinct marker labels, in order
    for (const auto& panel : panels)
        for (const auto& m : panel.markers)
            if (!m.label.empty() && std::find(names.begin(), names.end(), m.label) == names.end()) names.push_back(m.label);
    auto label_box = [&](const ChartPanel& panel, const ChartMarker& m, const std::string& label) {
        // as drawn below: right of the marker, or left of it at the right edge; above it, or below at the top
        const Axis& ax = panel.sweep->spec.x;
        const Axis& ay = panel.sweep->spec.y;
        const double cx = std::min(std::max((m.x - ax.lo) / (ax.hi - ax.lo), 0.0), 1.0) * o.panel_width;
        const double cy = (1.0 - std::min(std::max((m.y - ay.lo) / (ay.hi - ay.lo), 0.0), 1.0)) * o.panel_height;
        const double lw = text_width(label, f_tick);
        const bool right = cx + 8 + lw <= o.panel_width;
        const double x0 = right ? cx + 8 : std::max(cx - 8, lw) - lw;
        const double y1 = cy - 8 < f_tick ? cy + f_tick + 6 : cy - 8;
        return std::array<double, 4>{x0, y1 - f_tick, x0 + lw, y1 + 2};
    };
    bool numbered = false;
    for (const auto& panel : panels) {
        const Axis& ax = panel.sweep->spec.x;
        const Axis& ay = panel.sweep->spec.y;
        std::vector<std::array<double, 4>> boxes;  // per marker: its label's box (empty label: none)
        std::vector<std::pair<double, double>> dots;
        for (const auto& m : panel.markers) {
            if (text_width(m.label, f_tick) > 0.45 * o.panel_width) numbered = true;
            boxes.push_back(m.label.empty() ? std::array<double, 4>{0, 0, 0, 0} : label_box(panel, m, m.label));
            dots.emplace_back((m.x - ax.lo) / (ax.hi - ax.lo) * o.panel_width, (1.0 - (m.y - ay.lo) / (ay.hi - ay.lo)) * o.panel_height);
        }
        auto overlap = [](const std::array<double, 4>& p, const std::array<double, 4>& q) {
            return p[0] < q[2] && q[0] < p[2] && p[1] < q[3] && q[1] < p[3];
        };
        for (std::size_t a = 0; a < boxes.size(); ++a) {
            if (panel.markers[a].label.empty()) continue;
            for (std::size_t b = 0; b < boxes.size(); ++b) {
                if (a == b) continue;
                const std::array<double, 4> dot{dots[b].first - 5, dots[b].second - 5, dots[b].first + 5, dots[b].second + 5};
                if ((!panel.markers[b].label.empty() && overlap(boxes[a], boxes[b])) || overlap(boxes[a], dot)) numbered = true;
            }
        }
    }
    auto marker_text = [&](const ChartMarker& m) {
        if (!numbered || m.label.empty()) return m.label;
        return std::to_string(std::find(names.begin(), names.end(), m.label) - names.begin() + 1);
    };
    std::vector<std::pair<double, double>> item_pos;
    double lx = 10, ly_rel = 0;
    for (const auto& it : items) {
        const double w = 36 + text_width(it.text, f_legend);
        if (lx + w > width - 10 && lx > 10) {
            lx = 10;
            ly_rel += 24;
        }
        item_pos.emplace_back(lx, ly_rel);
        lx += w + 20;
    }
    // the key of the numbered markers: "1 NAME" entries, wrapped to the figure width
    std::vector<std::pair<double, double>> key_pos;
    double kx = 10, ky = ly_rel + 24 + 6;
    if (numbered) {
        for (std::size_t i = 0; i < names.size(); ++i) {
            const double w = text_width(std::to_string(i + 1) + "  " + names[i], f_legend);
            width = std::max(width, w + 20);
            if (kx + w > width - 10 && kx > 10) {
                kx = 10;
                ky += 22;
            }
            key_pos.emplace_back(kx, ky);
            kx += w + 24;
        }
    }
    const double head_size = fitted_size(o.title, f_head, width - 20, 12);
    const double header = o.title.empty() ? 10 : 40;
    const double legend_h = (items.empty() ? 10 : ly_rel + 24 + 16) + (numbered ? ky - (ly_rel + 24) + 22 : 0.0);
    const double height = header + rows * ch + legend_h;

    std::ostringstream s;
    s << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
    s << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << num(width) << "\" height=\"" << num(height) << "\" viewBox=\"0 0 "
      << num(width) << " " << num(height) << "\" font-family=\"DejaVu Sans, Helvetica, Arial, sans-serif\">\n";
    s << "<rect id=\"background\" x=\"0\" y=\"0\" width=\"" << num(width) << "\" height=\"" << num(height) << "\" fill=\"#ffffff\"/>\n";
    if (!o.title.empty())
        s << "<text id=\"title\" x=\"" << num(width / 2) << "\" y=\"26\" text-anchor=\"middle\" font-size=\"" << num(head_size)
          << "\" font-weight=\"bold\">" << esc(o.title) << "</text>\n";
    for (std::size_t pi = 0; pi < panels.size(); ++pi) {
        const ChartPanel& panel = panels[pi];
        const SweepResult& sw = *panel.sweep;
        const Axis& ax = sw.spec.x;
        const Axis& ay = sw.spec.y;
        const double ox = (pi % cols) * cw + ml + 5, oy = header + (pi / cols) * ch + mt;
        const double pw = o.panel_width, ph = o.panel_height;
        // a value far outside the window (a marker at k2 = -1e308, a huge confidence ellipse) is
        // drawn as if 10^4 panel sizes away: the same direction and a clipped line, never an
        // overflow to inf and a NaN coordinate
        auto X = [&](double x) { return ox + std::clamp((x - ax.lo) / (ax.hi - ax.lo), -1e4, 1e4) * pw; };
        auto Y = [&](double y) { return oy + ph - std::clamp((y - ay.lo) / (ay.hi - ay.lo), -1e4, 1e4) * ph; };
        const std::string id = "panel" + std::to_string(pi + 1);
        s << "<g id=\"" << id << "\">\n";
        // the panel title on one line; too wide, on two (split after "NAME:"), each shortened in
        // the middle with an ellipsis if it still does not fit
        {
            std::vector<std::string> lines{panel.title};
            const std::size_t colon = panel.title.find(": ");
            const double room = o.panel_width + 2 * mr;  // centred over the plot area
            if (text_width(panel.title, f_title) > room && colon != std::string::npos)
                lines = {panel.title.substr(0, colon + 1), panel.title.substr(colon + 2)};
            for (std::size_t li = 0; li < lines.size(); ++li) {
                const double size = fitted_size(lines[li], f_title, room, 11);
                const auto glyphs = [](const std::string& t) {
                    std::vector<std::string> g;
                    for (unsigned char c : t)
                        if ((c & 0xC0) != 0x80 || g.empty()) g.emplace_back(1, static_cast<char>(c));
                        else g.back() += static_cast<char>(c);
                    return g;
                };
                std::vector<std::string> g = glyphs(lines[li]);
                const auto fit = static_cast<std::size_t>(room / (0.62 * size));
                if (g.size() > fit && fit > 4) {
                    const std::size_t keep = fit - 1, head = keep / 2;
                    std::string t;
                    for (std::size_t k = 0; k < head; ++k) t += g[k];
                    t += "\u2026";
                    for (std::size_t k = g.size() - (keep - head); k < g.size(); ++k) t += g[k];
                    lines[li] = t;
                }
                const double y = oy - 12 - (lines.size() - 1 - li) * (size + 3);
                s << "<text id=\"" << id << "-title" << (li ? "2" : "") << "\" x=\"" << num(ox + pw / 2) << "\" y=\"" << num(y)
                  << "\" text-anchor=\"middle\" font-size=\"" << num(size) << "\">" << esc(lines[li]) << "</text>\n";
            }
        }
        s << "<clipPath id=\"" << id << "-clip\"><rect x=\"" << num(ox) << "\" y=\"" << num(oy) << "\" width=\"" << num(pw)
          << "\" height=\"" << num(ph) << "\"/></clipPath>\n";
        // regions, filled up to the boundaries: for each level c = 1, 2, 3 the set {class >= c}
        // (marching squares over the grid cells) painted over the level below; where the class
        // changes along a cell edge the edge point is where that edge meets a continued boundary
        // curve (exact), else the zero of the failing condition's margin interpolated linearly
        const int nx = ax.count, ny = ay.count;
        // boundary curve segments in data coordinates, with the lowest level whose set they bound
        // (plant Hopf: 1, ring Hopf: 2, string: 3)
        std::vector<std::array<double, 5>> segs;
        if (panel.boundaries)
            for (const auto& c : panel.boundaries->curves) {
                const double lvl = c.kind == BoundaryKind::PlantHopf ? 1 : c.kind == BoundaryKind::RingHopf ? 2 : 3;
                const std::size_t n = c.points.size();
                for (std::size_t k = 0; k + 1 < n + (c.closed ? 1 : 0); ++k) {
                    const auto& a = c.points[k];
                    const auto& b = c.points[(k + 1) % n];
                    segs.push_back({a.x, a.y, b.x, b.y, lvl});
                }
            }
        auto crossing = [&](int ia, int ja, int ib, int jb, int level) {
            // grid points a (inside level) and b (outside), neighbours along x or y
            const SweepPoint& pa = sw.at(ia, ja);
            const SweepPoint& pb = sw.at(ib, jb);
            const bool a_in = region_class(pa) >= level;
            const SweepPoint& in = a_in ? pa : pb;
            const SweepPoint& out = a_in ? pb : pa;
            const int cond = region_class(out);
            const bool lowfreq = out.lowfreq_margin <= 0.0;
            const double mi = condition_margin(in, cond, lowfreq), mo = condition_margin(out, cond, lowfreq);
            double t = (mi > 0.0 && mo <= 0.0 && mi - mo > 0.0) ? mi / (mi - mo) : 0.5;  // from `in` towards `out`
            const double xa = ax.value(ia), ya = ay.value(ja), xb = ax.value(ib), yb = ay.value(jb);
            const double xi = a_in ? xa : xb, yi = a_in ? ya : yb, xo = a_in ? xb : xa, yo = a_in ? yb : ya;
            double px = xi + t * (xo - xi), py = yi + t * (yo - yi);
            // snap to the first continued curve crossing this edge from the inside point among
            // those that bound this level's set (its edge is where the first condition fails)
            double best = 2.0;
            for (const auto& g : segs) {
                if (g[4] > level) continue;
                const double ex = xo - xi, ey = yo - yi, fx = g[2] - g[0], fy = g[3] - g[1];
                const double den = ex * fy - ey * fx;
                if (den == 0.0) continue;
                const double u = ((g[0] - xi) * fy - (g[1] - yi) * fx) / den;
                const double v = ((g[0] - xi) * ey - (g[1] - yi) * ex) / den;
                if (u < 0.0 || u > 1.0 || v < 0.0 || v > 1.0) continue;
                if (u < best) {
                    best = u;
                    px = xi + u * ex;
                    py = yi + u * ey;
                }
            }
            return std::pair<double, double>{px, py};
        };
        s << "<g id=\"" << id << "-regions\" clip-path=\"url(#" << id << "-clip)\" stroke-linejoin=\"round\" stroke-width=\"0.6\">\n";
        s << "<rect x=\"" << num(ox) << "\" y=\"" << num(oy) << "\" width=\"" << num(pw) << "\" height=\"" << num(ph) << "\" fill=\""
          << region_fill[0] << "\"/>\n";
        for (int level = 1; level <= (any_peak ? 4 : 3); ++level) {
            s << "<g class=\"level" << level << "\" fill=\"" << region_fill[level] << "\" stroke=\"" << region_fill[level] << "\">\n";
            auto inside = [&](int i, int j) { return region_class(sw.at(i, j)) >= level; };
            for (int j = 0; j + 1 < ny; ++j) {
                int run = -1;  // start of a run of cells wholly inside
                for (int i = 0; i + 1 <= nx; ++i) {
                    const bool full = i + 1 < nx && inside(i, j) && inside(i + 1, j) && inside(i, j + 1) && inside(i + 1, j + 1);
                    if (full) {
                        if (run < 0) run = i;
                        continue;
                    }
                    if (run >= 0) {
                        s << "<rect x=\"" << num(X(ax.value(run))) << "\" y=\"" << num(Y(ay.value(j + 1))) << "\" width=\""
                          << num(X(ax.value(i)) - X(ax.value(run))) << "\" height=\"" << num(Y(ay.value(j)) - Y(ay.value(j + 1))) << "\"/>\n";
                        run = -1;
                    }
                    if (i + 1 >= nx) break;
                    // a cell with some corners inside: its inside part as one polygon
                    const int ci[4] = {i, i + 1, i + 1, i}, cj[4] = {j, j, j + 1, j + 1};
                    bool in[4];
                    int count = 0;
                    for (int k = 0; k < 4; ++k) count += (in[k] = inside(ci[k], cj[k])) ? 1 : 0;
                    if (count == 0) continue;
                    s << "<polygon points=\"";
                    for (int k = 0; k < 4; ++k) {
                        const int l = (k + 1) % 4;
                        if (in[k]) s << num(X(ax.value(ci[k]))) << "," << num(Y(ay.value(cj[k]))) << " ";
                        if (in[k] != in[l]) {
                            const auto [px, py] = crossing(ci[k], cj[k], ci[l], cj[l], level);
                            s << num(X(px)) << "," << num(Y(py)) << " ";
                        }
                    }
                    s << "\"/>\n";
                }
            }
            s << "</g>\n";
        }
        s << "</g>\n";
        // boundaries
        s << "<g id=\"" << id << "-boundaries\" clip-path=\"url(#" << id << "-clip)\" fill=\"none\" stroke-linejoin=\"round\">\n";
        if (panel.boundaries) {
            for (const auto& c : panel.boundaries->curves) {
                if (c.points.size() < 2) continue;
                const Style st = curve_style(c.kind);
                s << "<polyline class=\"" << subkind_name(c.kind) << "\" stroke=\"" << st.colour << "\" stroke-width=\"" << st.width << "\"";
                if (*st.dash) s << " stroke-dasharray=\"" << st.dash << "\"";
                s << " points=\"";
                for (const auto& p : c.points) s << num(X(p.x)) << "," << num(Y(p.y)) << " ";
                if (c.closed) s << num(X(c.points.front().x)) << "," << num(Y(c.points.front().y));
                s << "\"/>\n";
            }
        }
        s << "</g>\n";
        // axes
        s << "<g id=\"" << id << "-axes\" font-size=\"" << num(f_tick) << "\" stroke-linecap=\"square\">\n";
        s << "<rect x=\"" << num(ox) << "\" y=\"" << num(oy) << "\" width=\"" << num(pw) << "\" height=\"" << num(ph)
          << "\" fill=\"none\" stroke=\"#000\" stroke-width=\"1\"/>\n";
        // tick labels at least 1.6 label widths apart (no crowded numbers): the next nice step otherwise
        double sx = nice_step(ax.hi - ax.lo);
        for (int k = 0; k < 8 && pw / ((ax.hi - ax.lo) / sx) < text_width(tick_text(ax.hi, sx), f_tick) * 1.6; ++k) sx = nice_step(10.0 * sx);
        const double sy = nice_step(ay.hi - ay.lo);
        for (const double t : tick_values(ax.lo, ax.hi, sx)) {
            s << "<line x1=\"" << num(X(t)) << "\" y1=\"" << num(oy + ph) << "\" x2=\"" << num(X(t)) << "\" y2=\"" << num(oy + ph + 5)
              << "\" stroke=\"#000\"/>\n";
            s << "<text x=\"" << num(X(t)) << "\" y=\"" << num(oy + ph + 19) << "\" text-anchor=\"middle\">" << tick_text(t, sx) << "</text>\n";
        }
        for (const double t : tick_values(ay.lo, ay.hi, sy)) {
            s << "<line x1=\"" << num(ox - 5) << "\" y1=\"" << num(Y(t)) << "\" x2=\"" << num(ox) << "\" y2=\"" << num(Y(t))
              << "\" stroke=\"#000\"/>\n";
            s << "<text x=\"" << num(ox - 8) << "\" y=\"" << num(Y(t) + 4.5) << "\" text-anchor=\"end\">" << tick_text(t, sy) << "</text>\n";
        }
        s << "<text x=\"" << num(ox + pw / 2) << "\" y=\"" << num(oy + ph + 40) << "\" text-anchor=\"middle\" font-size=\"" << num(f_label)
          << "\">" << esc(axis_label(sw.spec.model, ax.name)) << "</text>\n";
        s << "<text transform=\"translate(" << num(ox - 52) << "," << num(oy + ph / 2) << ") rotate(-90)\" text-anchor=\"middle\" font-size=\""
          << num(f_label) << "\">" << esc(axis_label(sw.spec.model, ay.name)) << "</text>\n";
        s << "</g>\n";
        // confidence ellipses: {d : d^T C^-1 d <= 5.991} (chi-square, 2 degrees of freedom, 95 %),
        // drawn as C^(1/2) times a circle of radius sqrt(5.991) (a segment when C is singular)
        s << "<g id=\"" << id << "-ellipses\" clip-path=\"url(#" << id << "-clip)\" fill=\"#000000\" fill-opacity=\"0.08\" stroke=\"#000\" stroke-width=\"1.3\">\n";
        for (const auto& m : panel.markers) {
            if (!m.has_ellipse) continue;
            const double a = m.cov_xx, b = m.cov_xy, d = m.cov_yy;
            const double tr = 0.5 * (a + d), disc = std::sqrt(std::max(0.0, 0.25 * (a - d) * (a - d) + b * b));
            const double l1 = std::max(0.0, tr + disc), l2 = std::max(0.0, tr - disc);
            const double phi = 0.5 * std::atan2(2.0 * b, a - d);
            const double r = std::sqrt(5.991464547107979);
            s << "<polygon points=\"";
            for (int k = 0; k < 96; ++k) {
                const double t = 2.0 * M_PI * k / 96.0;
                const double u = r * std::sqrt(l1) * std::cos(t), v = r * std::sqrt(l2) * std::sin(t);
                s << num(X(m.x + u * std::cos(phi) - v * std::sin(phi))) << "," << num(Y(m.y + u * std::sin(phi) + v * std::cos(phi))) << " ";
            }
            s << "\"/>\n";
        }
        s << "</g>\n";
        if (panel.path.size() >= 2) {
            s << "<g id=\"" << id << "-path\" clip-path=\"url(#" << id << "-clip)\">\n<polyline fill=\"none\" stroke=\"#252525\" stroke-width=\"1.2\" "
              << "stroke-dasharray=\"4,2\" points=\"";
            for (const auto& [px, py] : panel.path) s << num(X(px)) << "," << num(Y(py)) << " ";
            s << "\"/>\n";
            for (const auto& [px, py] : panel.path) s << "<circle cx=\"" << num(X(px)) << "\" cy=\"" << num(Y(py)) << "\" r=\"1.8\" fill=\"#252525\"/>\n";
            s << "</g>\n";
        }
        // markers: inside the window as a dot with its label; outside it on the nearest edge as
        // an open triangle pointing out of the window, the label saying so
        s << "<g id=\"" << id << "-markers\" font-size=\"" << num(f_tick) << "\">\n";
        // the dots first (a label is drawn over them, never under one), then each label at the
        // first of four places around its dot (upper right, upper left, lower right, lower left)
        // that stays in the plot and clears every dot and every label placed before it
        std::vector<std::array<double, 4>> taken;
        std::vector<std::pair<double, double>> at;
        for (const auto& m : panel.markers) {
            const bool out = !(m.x >= ax.lo && m.x <= ax.hi && m.y >= ay.lo && m.y <= ay.hi);
            const double cx = std::min(std::max(X(m.x), ox), ox + pw), cy = std::min(std::max(Y(m.y), oy), oy + ph);
            at.emplace_back(cx, cy);
            taken.push_back({cx - 5.5, cy - 5.5, cx + 5.5, cy + 5.5});
            if (out) {
                const double dx = X(m.x) - cx, dy = Y(m.y) - cy, n = std::hypot(dx, dy);
                const double ux = n > 0 ? dx / n : 0.0, uy = n > 0 ? dy / n : -1.0;
                s << "<polygon points=\"" << num(cx + 7 * ux) << "," << num(cy + 7 * uy) << " " << num(cx - 6 * ux - 5 * uy) << ","
                  << num(cy - 6 * uy + 5 * ux) << " " << num(cx - 6 * ux + 5 * uy) << "," << num(cy - 6 * uy - 5 * ux)
                  << "\" fill=\"#fff\" stroke=\"#000\" stroke-width=\"1.5\"/>\n";
            } else {
                s << "<circle cx=\"" << num(cx) << "\" cy=\"" << num(cy) << "\" r=\"4.5\" fill=\"#000\" stroke=\"#fff\" stroke-width=\"1.2\"/>\n";
            }
        }
        for (std::size_t k = 0; k < panel.markers.size(); ++k) {
            const ChartMarker& m = panel.markers[k];
            const bool out = !(m.x >= ax.lo && m.x <= ax.hi && m.y >= ay.lo && m.y <= ay.hi);
            // the name, or its number in the key (see above)
            const std::string label = out && !numbered ? m.label + " (outside)" : marker_text(m);
            if (label.empty()) continue;
            const double lw = text_width(label, f_tick);
            const auto [cx, cy] = at[k];
            std::array<double, 4> box{};
            bool placed = false;
            for (int c = 0; c < 4 && !placed; ++c) {
                const double x0 = c % 2 == 0 ? cx + 7 : cx - 7 - lw, baseline = c < 2 ? cy - 7 : cy + f_tick + 5;
                box = {x0, baseline - f_tick + 2, x0 + lw, baseline + 2};
                if (box[0] < ox || box[2] > ox + pw || box[1] < oy || box[3] > oy + ph) continue;
                placed = true;
                for (std::size_t q = 0; q < taken.size() && placed; ++q)
                    if (q != k && box[0] < taken[q][2] && taken[q][0] < box[2] && box[1] < taken[q][3] && taken[q][1] < box[3]) placed = false;
            }
            if (!placed) {  // nowhere clear: the upper right (left at the right edge), as before
                const double x0 = cx + 8 + lw <= ox + pw ? cx + 7 : std::max(cx - 7, ox + lw) - lw;
                const double baseline = cy - 8 < oy + f_tick ? cy + f_tick + 5 : cy - 7;
                box = {x0, baseline - f_tick + 2, x0 + lw, baseline + 2};
            }
            taken.push_back(box);
            s << "<text x=\"" << num(box[0]) << "\" y=\"" << num(box[3] - 2) << "\" text-anchor=\"start\" paint-order=\"stroke\" stroke=\"#fff\" "
              << "stroke-width=\"3\">" << esc(label) << "</text>\n";
        }
        s << "</g>\n";
        s << "</g>\n";
    }
    // legend: only what the figure shows
    const double ly = header + rows * ch + 8;
    s << "<g id=\"legend\" font-size=\"" << num(f_legend) << "\">\n";
    for (std::size_t i = 0; i < items.size(); ++i) {
        const Item& it = items[i];
        const double x = item_pos[i].first, y = ly + item_pos[i].second;
        switch (it.type) {
            case 0:
                s << "<rect x=\"" << num(x) << "\" y=\"" << num(y) << "\" width=\"26\" height=\"15\" fill=\"" << region_fill[it.index]
                  << "\" stroke=\"#555\" stroke-width=\"0.5\"/>\n";
                break;
            case 1: {
                const Style st = curve_style(kinds[it.index]);
                s << "<line x1=\"" << num(x) << "\" y1=\"" << num(y + 7.5) << "\" x2=\"" << num(x + 26) << "\" y2=\"" << num(y + 7.5)
                  << "\" stroke=\"" << st.colour << "\" stroke-width=\"" << st.width << "\"";
                if (*st.dash) s << " stroke-dasharray=\"" << st.dash << "\"";
                s << "/>\n";
                break;
            }
            case 2:
                s << "<circle cx=\"" << num(x + 13) << "\" cy=\"" << num(y + 7.5) << "\" r=\"4.5\" fill=\"#000\"/>\n";
                break;
            case 3:
                s << "<ellipse cx=\"" << num(x + 13) << "\" cy=\"" << num(y + 7.5) << "\" rx=\"12\" ry=\"6\" fill=\"#000\" fill-opacity=\"0.08\" "
                  << "stroke=\"#000\" stroke-width=\"1.3\"/>\n";
                break;
            case 5:
                s << "<line x1=\"" << num(x) << "\" y1=\"" << num(y + 7.5) << "\" x2=\"" << num(x + 26) << "\" y2=\"" << num(y + 7.5)
                  << "\" stroke=\"#252525\" stroke-width=\"1.2\" stroke-dasharray=\"4,2\"/><circle cx=\"" << num(x + 13) << "\" cy=\"" << num(y + 7.5)
                  << "\" r=\"1.8\" fill=\"#252525\"/>\n";
                break;
            default:
                s << "<polygon points=\"" << num(x + 20) << "," << num(y + 7.5) << " " << num(x + 7) << "," << num(y + 2.5) << " " << num(x + 7)
                  << "," << num(y + 12.5) << "\" fill=\"#fff\" stroke=\"#000\" stroke-width=\"1.5\"/>\n";
        }
        s << "<text x=\"" << num(x + 34) << "\" y=\"" << num(y + 12.5) << "\">" << esc(it.text) << "</text>\n";
    }
    for (std::size_t i = 0; i < key_pos.size(); ++i)
        s << "<text class=\"key\" x=\"" << num(key_pos[i].first) << "\" y=\"" << num(ly + key_pos[i].second + 12.5) << "\"><tspan font-weight=\"bold\">"
          << (i + 1) << "</tspan>  " << esc(names[i]) << "</text>\n";
    s << "</g>\n</svg>\n";
    return s.str();
}

namespace {
const char* palette[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2",
                         "#7f7f7f", "#bcbd22", "#17becf", "#393b79", "#637939", "#8c6d31", "#843c39"};
}  // namespace

std::string plot_colour(std::size_t i) { return palette[i % 14]; }

std::string render_line_plots_svg(const std::vector<PlotPanel>& panels, const PlotOptions& o) {
    if (panels.empty()) throw std::invalid_argument("a plot needs at least one panel");
    // a size that is not finite is a caller's bug (the guard of every number written), caught
    // before any arithmetic converts it to an integer
    if (!std::isfinite(o.panel_width) || !std::isfinite(o.panel_height))
        throw std::logic_error("a non-finite figure size (" + std::to_string(o.panel_width) + " x " + std::to_string(o.panel_height) +
                               ") reached the SVG writer");
    const int cols = std::max(1, std::min<int>(o.columns, static_cast<int>(panels.size())));
    const int rows = (static_cast<int>(panels.size()) + cols - 1) / cols;
    const double ml = 70, mr = 18, mt = 36, mb = 54;  // type as in the charts: readable at a column width
    const double cw = o.panel_width + ml + mr, ch = o.panel_height + mt + mb;
    const double header = o.title.empty() ? 10 : 34;
    // as wide as the panels, or wider where the title needs it at 12 px (long names are not cut off)
    const double width = std::max(cols * cw + 10, text_width(o.title, 12) + 20);
    // legend entries: the series names of the first panel
    std::vector<std::pair<std::string, std::string>> entries;
    std::vector<bool> dashed_entries;
    std::vector<std::pair<std::string, std::string>> fill_entries;
    if (o.legend)
        for (const auto& f : panels.front().fills)
            if (!f.name.empty()) fill_entries.emplace_back(f.name, f.colour);
    if (o.legend) {
        std::size_t i = 0;
        for (const auto& sr : panels.front().series) {
            const std::string colour = sr.colour.empty() ? palette[i % 14] : sr.colour;
            ++i;
            // a series drawn in pieces (same name, colour and dash) has one legend entry
            bool seen = false;
            for (std::size_t k = 0; k < entries.size(); ++k)
                seen = seen || (entries[k].first == sr.name && entries[k].second == colour && dashed_entries[k] == sr.dashed);
            if (seen) continue;
            entries.emplace_back(sr.name, colour);
            dashed_entries.push_back(sr.dashed);
        }
    }
    // one slot per entry, wide enough for the longest name (13 px text: about 7.8 px a character)
    std::size_t longest = 0;
    for (const auto& e : entries) longest = std::max(longest, e.first.size());
    for (const auto& e : fill_entries) longest = std::max(longest, e.first.size());
    const double slot = std::max(150.0, 29.0 + 7.8 * static_cast<double>(longest) + 14.0);
    const int per_row = std::max(1, static_cast<int>((width - 20) / slot));
    const std::size_t legend_count = entries.size() + fill_entries.size();
    const double legend_h = legend_count == 0 ? 10 : 20.0 * ((legend_count + per_row - 1) / per_row) + 12;
    // the note, wrapped at spaces to the figure's width (13 px text: about 7.2 px a character)
    std::vector<std::string> note_lines;
    {
        const std::size_t per_line = static_cast<std::size_t>(std::max(20.0, (width - 20) / 7.2));
        std::istringstream words(o.note);
        std::string word, line;
        while (words >> word) {
            if (!line.empty() && line.size() + 1 + word.size() > per_line) {
                note_lines.push_back(line);
                line.clear();
            }
            line += (line.empty() ? "" : " ") + word;
        }
        if (!line.empty()) note_lines.push_back(line);
    }
    const double note_h = 18.0 * static_cast<double>(note_lines.size()) + (note_lines.empty() ? 0 : 4);
    const double height = header + rows * ch + legend_h + note_h;
    std::ostringstream s;
    svg_preamble(s, width, height, o.title, fitted_size(o.title, 15, width - 20, 12));
    for (std::size_t pi = 0; pi < panels.size(); ++pi) {
        const PlotPanel& p = panels[pi];
        double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
        for (const auto& sr : p.series)
            for (std::size_t k = 0; k < sr.x.size() && k < sr.y.size(); ++k) {
                if (!std::isfinite(sr.x[k]) || !std::isfinite(sr.y[k])) continue;
                x0 = std::min(x0, sr.x[k]); x1 = std::max(x1, sr.x[k]);
                y0 = std::min(y0, sr.y[k]); y1 = std::max(y1, sr.y[k]);
            }
        for (const auto& m : p.markers) {
            x0 = std::min(x0, m.x); x1 = std::max(x1, m.x);
            y0 = std::min(y0, m.y); y1 = std::max(y1, m.y);
        }
        // a range below 1e-9 of its values (a constant speed, to rounding) is drawn as +-0.5 around it:
        // ticks finer than that would be below the spacing of doubles
        auto widen = [](double& lo, double& hi) {
            if (lo > hi) { lo = 0; hi = 0; }  // no finite data
            if (!(hi - lo > 1e-9 * std::max({1.0, std::abs(lo), std::abs(hi)}))) {
                const double mid = 0.5 * (lo + hi);
                lo = mid - 0.5;
                hi = mid + 0.5;
            }
        };
        const bool fixed = std::isfinite(p.x_min) && std::isfinite(p.x_max) && std::isfinite(p.y_min) && std::isfinite(p.y_max) &&
                           p.x_max > p.x_min && p.y_max > p.y_min;
        double sx = 0.0, sy = 0.0;
        if (fixed) {
            x0 = p.x_min; x1 = p.x_max; y0 = p.y_min; y1 = p.y_max;
            sx = nice_step(x1 - x0);
            sy = nice_step(y1 - y0);
        } else {
            widen(x0, x1);
            if (p.y_from_floor && y0 >= p.y_floor && y1 > p.y_floor) y0 = p.y_floor;
            widen(y0, y1);
            const double pad = 0.04 * (y1 - y0);
            const bool floored = y0 >= p.y_floor;
            y0 -= pad;
            y1 += pad;
            sx = nice_step(x1 - x0);
            sy = nice_step(y1 - y0);
            x0 = std::floor(x0 / sx) * sx; x1 = std::ceil(x1 / sx) * sx;
            y0 = std::floor(y0 / sy) * sy; y1 = std::ceil(y1 / sy) * sy;
            if (floored && y0 < p.y_floor) y0 = p.y_floor;
        }
        const double ox = (pi % cols) * cw + ml + 5, oy = header + (pi / cols) * ch + mt;
        const double pw = o.panel_width, ph = o.panel_height;
        auto X = [&](double x) { return ox + (x - x0) / (x1 - x0) * pw; };
        auto Y = [&](double y) { return oy + ph - (y - y0) / (y1 - y0) * ph; };
        const std::string id = "plot" + std::to_string(pi + 1);
        s << "<g id=\"" << id << "\">\n";
        s << "<text id=\"" << id << "-title\" x=\"" << num(ox + pw / 2) << "\" y=\"" << num(oy - 10) << "\" text-anchor=\"middle\" font-size=\"14\">"
          << esc(p.title) << "</text>\n";
        s << "<g id=\"" << id << "-axes\" font-size=\"13\">\n";
        s << "<rect x=\"" << num(ox) << "\" y=\"" << num(oy) << "\" width=\"" << num(pw) << "\" height=\"" << num(ph)
          << "\" fill=\"none\" stroke=\"#000\"/>\n";
        for (const double t : tick_values(x0, x1, sx)) {
            s << "<line x1=\"" << num(X(t)) << "\" y1=\"" << num(oy) << "\" x2=\"" << num(X(t)) << "\" y2=\"" << num(oy + ph)
              << "\" stroke=\"#e5e5e5\"/>\n";
            s << "<text x=\"" << num(X(t)) << "\" y=\"" << num(oy + ph + 18) << "\" text-anchor=\"middle\">" << tick_text(t, sx) << "</text>\n";
        }
        for (const double t : tick_values(y0, y1, sy)) {
            s << "<line x1=\"" << num(ox) << "\" y1=\"" << num(Y(t)) << "\" x2=\"" << num(ox + pw) << "\" y2=\"" << num(Y(t))
              << "\" stroke=\"#e5e5e5\"/>\n";
            s << "<text x=\"" << num(ox - 6) << "\" y=\"" << num(Y(t) + 4.5) << "\" text-anchor=\"end\">" << tick_text(t, sy) << "</text>\n";
        }
        s << "<text x=\"" << num(ox + pw / 2) << "\" y=\"" << num(oy + ph + 40) << "\" text-anchor=\"middle\" font-size=\"14\">" << esc(p.x_label)
          << "</text>\n";
        s << "<text transform=\"translate(" << num(ox - 52) << "," << num(oy + ph / 2) << ") rotate(-90)\" text-anchor=\"middle\" font-size=\"14\">"
          << esc(p.y_label) << "</text>\n";
        s << "</g>\n";
        if (!p.fills.empty()) {
            s << "<clipPath id=\"" << id << "-clip\"><rect x=\"" << num(ox) << "\" y=\"" << num(oy) << "\" width=\"" << num(pw) << "\" height=\"" << num(ph)
              << "\"/></clipPath>\n";
            s << "<g id=\"" << id << "-fills\" clip-path=\"url(#" << id << "-clip)\" stroke=\"none\">\n";
            for (const auto& f : p.fills)
                for (const auto& poly : f.polygons) {
                    s << "<polygon fill=\"" << f.colour << "\" fill-opacity=\"" << num(f.opacity) << "\" points=\"";
                    for (const auto& [px, py] : poly)
                        if (std::isfinite(px) && std::isfinite(py)) s << num(X(px)) << "," << num(Y(py)) << " ";
                    s << "\"><title>" << esc(f.name) << "</title></polygon>\n";
                }
            s << "</g>\n";
        }
        s << "<g id=\"" << id << "-series\" fill=\"none\" stroke-width=\"1.4\" stroke-linejoin=\"round\">\n";
        std::size_t si = 0;
        for (const auto& sr : p.series) {
            const std::string colour = sr.colour.empty() ? palette[si % 14] : sr.colour;
            ++si;
            s << "<polyline stroke=\"" << colour << "\"" << (sr.dashed ? " stroke-dasharray=\"5,3\"" : "") << " points=\"";
            for (std::size_t k = 0; k < sr.x.size() && k < sr.y.size(); ++k)
                if (std::isfinite(sr.x[k]) && std::isfinite(sr.y[k])) s << num(X(sr.x[k])) << "," << num(Y(sr.y[k])) << " ";
            s << "\"><title>" << esc(sr.name) << "</title></polyline>\n";
        }
        s << "</g>\n";
        s << "<g id=\"" << id << "-markers\" stroke-width=\"2\" font-size=\"9\">\n";
        for (const auto& m : p.markers) {
            const double cx = X(m.x), cy = Y(m.y);
            s << "<path d=\"M" << num(cx - 4) << "," << num(cy - 4) << " L" << num(cx + 4) << "," << num(cy + 4) << " M" << num(cx - 4) << ","
              << num(cy + 4) << " L" << num(cx + 4) << "," << num(cy - 4) << "\" stroke=\"" << m.colour << "\"/>\n";
            if (!m.label.empty())
                s << "<text x=\"" << num(cx + 6) << "\" y=\"" << num(cy - 5) << "\" stroke=\"none\" fill=\"" << m.colour << "\">" << esc(m.label) << "</text>\n";
        }
        s << "</g>\n</g>\n";
    }
    if (legend_count > 0) {
        const double ly = header + rows * ch + 4;
        s << "<g id=\"legend\" font-size=\"13\">\n";
        for (std::size_t i = 0; i < entries.size(); ++i) {
            const double x = 10 + (i % per_row) * slot, y = ly + (i / per_row) * 20;
            s << "<line x1=\"" << num(x) << "\" y1=\"" << num(y + 7) << "\" x2=\"" << num(x + 24) << "\" y2=\"" << num(y + 7)
              << "\" stroke=\"" << entries[i].second << "\" stroke-width=\"2\"" << (dashed_entries[i] ? " stroke-dasharray=\"5,3\"" : "")
              << "/>\n<text x=\"" << num(x + 29) << "\" y=\"" << num(y + 11) << "\">" << esc(entries[i].first) << "</text>\n";
        }
        for (std::size_t k = 0; k < fill_entries.size(); ++k) {
            const std::size_t i = entries.size() + k;
            const double x = 10 + (i % per_row) * slot, y = ly + (i / per_row) * 20;
            s << "<rect x=\"" << num(x) << "\" y=\"" << num(y) << "\" width=\"24\" height=\"14\" fill=\"" << fill_entries[k].second
              << "\" fill-opacity=\"0.45\"/>\n<text x=\"" << num(x + 29) << "\" y=\"" << num(y + 11) << "\">" << esc(fill_entries[k].first) << "</text>\n";
        }
        s << "</g>\n";
    }
    for (std::size_t i = 0; i < note_lines.size(); ++i) {
        const double y = height - 6 - 18.0 * static_cast<double>(note_lines.size() - 1 - i);
        s << "<text" << (i == 0 ? " id=\"note\"" : "") << " x=\"10\" y=\"" << num(y) << "\" font-size=\"13\">" << esc(note_lines[i]) << "</text>\n";
    }
    s << "</svg>\n";
    return s.str();
}

}  // namespace ddemap
