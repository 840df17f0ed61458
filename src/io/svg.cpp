#include "ddemap/io/svg.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace ddemap {

namespace {

const char* region_fill[4] = {"#d73027", "#fc8d59", "#fee090", "#91bfdb"};
const char* region_name[4] = {"plant unstable", "ring unstable", "string unstable", "string stable"};

std::string esc(const std::string& s) {
    std::string o;
    for (char c : s) {
        switch (c) {
            case '&': o += "&amp;"; break;
            case '<': o += "&lt;"; break;
            case '>': o += "&gt;"; break;
            case '"': o += "&quot;"; break;
            default: o += c;
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

double nice_step(double range) {
    const double raw = range / 5.0;
    const double p = std::pow(10.0, std::floor(std::log10(raw)));
    const double m = raw / p;
    return (m < 1.5 ? 1.0 : m < 3.5 ? 2.0 : m < 7.5 ? 5.0 : 10.0) * p;
}

/// XML declaration, the svg element (width x height px), a white background and the title.
void svg_preamble(std::ostringstream& s, double width, double height, const std::string& title) {
    s << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
    s << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << num(width) << "\" height=\"" << num(height)
      << "\" viewBox=\"0 0 " << num(width) << " " << num(height) << "\" font-family=\"DejaVu Sans, Helvetica, Arial, sans-serif\">\n";
    s << "<rect id=\"background\" x=\"0\" y=\"0\" width=\"" << num(width) << "\" height=\"" << num(height) << "\" fill=\"#ffffff\"/>\n";
    if (!title.empty()) {
        s << "<text id=\"title\" x=\"" << num(width / 2) << "\" y=\"22\" text-anchor=\"middle\" font-size=\"15\" font-weight=\"bold\">"
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
        case BoundaryKind::LowFrequency: return {"#08519c", "6,3", 1.8, "string boundary, low frequency (c2 = 0)"};
        case BoundaryKind::Peak: return {"#6a3d9a", "2,2", 1.8, "string boundary, |Gamma| peak = 1"};
    }
    return {"#000", "", 1.0, ""};
}

}  // namespace

int region_class(const SweepPoint& p) {
    if (!p.plant_stable) return 0;
    if (!p.ring_stable) return 1;
    if (!p.string_stable) return 2;
    return 3;
}

std::string axis_label(const std::string& model, const std::string& parameter) {
    for (const auto& s : model_parameters(model))
        if (s.name == parameter) return parameter + " [" + s.unit + "]";
    return parameter;
}

std::string render_chart_svg(const std::vector<ChartPanel>& panels, const ChartOptions& o) {
    if (panels.empty()) throw std::invalid_argument("a chart needs at least one panel");
    for (const auto& p : panels)
        if (p.sweep == nullptr) throw std::invalid_argument("a chart panel needs a sweep");
    const int cols = std::max(1, std::min<int>(o.columns, static_cast<int>(panels.size())));
    const int rows = (static_cast<int>(panels.size()) + cols - 1) / cols;
    const double ml = 62, mr = 16, mt = 34, mb = 48;  // margins around each plot area
    const double cw = o.panel_width + ml + mr, ch = o.panel_height + mt + mb;
    const double header = o.title.empty() ? 10 : 34;
    const double width = cols * cw + 10;
    // legend rows: 4 swatches and 4 line styles, about 150 and 260 px each
    const int per_row_regions = std::max(1, static_cast<int>((width - 20) / 150));
    const int per_row_lines = std::max(1, static_cast<int>((width - 20) / 280));
    const double legend_h = 20.0 * ((4 + per_row_regions - 1) / per_row_regions + (4 + per_row_lines - 1) / per_row_lines) + 22;
    const double height = header + rows * ch + legend_h;

    std::ostringstream s;
    svg_preamble(s, width, height, o.title);
    for (std::size_t pi = 0; pi < panels.size(); ++pi) {
        const ChartPanel& panel = panels[pi];
        const SweepResult& sw = *panel.sweep;
        const Axis& ax = sw.spec.x;
        const Axis& ay = sw.spec.y;
        const double ox = (pi % cols) * cw + ml + 5, oy = header + (pi / cols) * ch + mt;
        const double pw = o.panel_width, ph = o.panel_height;
        auto X = [&](double x) { return ox + (x - ax.lo) / (ax.hi - ax.lo) * pw; };
        auto Y = [&](double y) { return oy + ph - (y - ay.lo) / (ay.hi - ay.lo) * ph; };
        const std::string id = "panel" + std::to_string(pi + 1);
        s << "<g id=\"" << id << "\">\n";
        s << "<text id=\"" << id << "-title\" x=\"" << num(ox + pw / 2) << "\" y=\"" << num(oy - 10)
          << "\" text-anchor=\"middle\" font-size=\"12\">" << esc(panel.title) << "</text>\n";
        s << "<clipPath id=\"" << id << "-clip\"><rect x=\"" << num(ox) << "\" y=\"" << num(oy) << "\" width=\"" << num(pw)
          << "\" height=\"" << num(ph) << "\"/></clipPath>\n";
        // regions: run-length rectangles per grid row, each cell centred on its grid point
        s << "<g id=\"" << id << "-regions\" clip-path=\"url(#" << id << "-clip)\" shape-rendering=\"crispEdges\">\n";
        const int nx = ax.count, ny = ay.count;
        const double dx = (ax.hi - ax.lo) / (nx - 1), dy = (ay.hi - ay.lo) / (ny - 1);
        for (int iy = 0; iy < ny; ++iy) {
            int start = 0;
            for (int ix = 1; ix <= nx; ++ix) {
                const int c0 = region_class(sw.at(start, iy));
                if (ix < nx && region_class(sw.at(ix, iy)) == c0) continue;
                const double x0 = std::max(ax.lo, ax.value(start) - dx / 2), x1 = std::min(ax.hi, ax.value(ix - 1) + dx / 2);
                const double y0 = std::max(ay.lo, ay.value(iy) - dy / 2), y1 = std::min(ay.hi, ay.value(iy) + dy / 2);
                s << "<rect x=\"" << num(X(x0)) << "\" y=\"" << num(Y(y1)) << "\" width=\"" << num(X(x1) - X(x0) + 0.3)
                  << "\" height=\"" << num(Y(y0) - Y(y1) + 0.3) << "\" fill=\"" << region_fill[c0] << "\"/>\n";
                start = ix;
            }
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
        s << "<g id=\"" << id << "-axes\" font-size=\"10\" stroke-linecap=\"square\">\n";
        s << "<rect x=\"" << num(ox) << "\" y=\"" << num(oy) << "\" width=\"" << num(pw) << "\" height=\"" << num(ph)
          << "\" fill=\"none\" stroke=\"#000\" stroke-width=\"1\"/>\n";
        const double sx = nice_step(ax.hi - ax.lo), sy = nice_step(ay.hi - ay.lo);
        // ticks by index (at most 1000): a step below the spacing of the values never ends a t += step loop
        const double tx0 = std::ceil(ax.lo / sx - 1e-9) * sx, ty0 = std::ceil(ay.lo / sy - 1e-9) * sy;
        for (int i = 0; i <= 1000 && tx0 + i * sx <= ax.hi + 1e-9 * sx; ++i) {
            const double t = tx0 + i * sx;
            s << "<line x1=\"" << num(X(t)) << "\" y1=\"" << num(oy + ph) << "\" x2=\"" << num(X(t)) << "\" y2=\"" << num(oy + ph + 5)
              << "\" stroke=\"#000\"/>\n";
            s << "<text x=\"" << num(X(t)) << "\" y=\"" << num(oy + ph + 17) << "\" text-anchor=\"middle\">" << tick_text(t, sx) << "</text>\n";
        }
        for (int i = 0; i <= 1000 && ty0 + i * sy <= ay.hi + 1e-9 * sy; ++i) {
            const double t = ty0 + i * sy;
            s << "<line x1=\"" << num(ox - 5) << "\" y1=\"" << num(Y(t)) << "\" x2=\"" << num(ox) << "\" y2=\"" << num(Y(t))
              << "\" stroke=\"#000\"/>\n";
            s << "<text x=\"" << num(ox - 8) << "\" y=\"" << num(Y(t) + 3.5) << "\" text-anchor=\"end\">" << tick_text(t, sy) << "</text>\n";
        }
        s << "<text x=\"" << num(ox + pw / 2) << "\" y=\"" << num(oy + ph + 36) << "\" text-anchor=\"middle\" font-size=\"12\">"
          << esc(axis_label(sw.spec.model, ax.name)) << "</text>\n";
        s << "<text transform=\"translate(" << num(ox - 44) << "," << num(oy + ph / 2) << ") rotate(-90)\" text-anchor=\"middle\" font-size=\"12\">"
          << esc(axis_label(sw.spec.model, ay.name)) << "</text>\n";
        s << "</g>\n";
        // markers
        s << "<g id=\"" << id << "-markers\" font-size=\"10\">\n";
        for (const auto& m : panel.markers) {
            s << "<circle cx=\"" << num(X(m.x)) << "\" cy=\"" << num(Y(m.y)) << "\" r=\"4\" fill=\"#000\" stroke=\"#fff\" stroke-width=\"1.2\"/>\n";
            const bool right = X(m.x) < ox + pw * 0.6;
            s << "<text x=\"" << num(X(m.x) + (right ? 7 : -7)) << "\" y=\"" << num(Y(m.y) - 6) << "\" text-anchor=\""
              << (right ? "start" : "end") << "\" paint-order=\"stroke\" stroke=\"#fff\" stroke-width=\"3\">" << esc(m.label) << "</text>\n";
        }
        s << "</g>\n";
        s << "</g>\n";
    }
    // legend: region swatches, then line styles, wrapped to the figure width
    const double ly = header + rows * ch + 8;
    s << "<g id=\"legend\" font-size=\"11\">\n";
    double lx = 10, row_y = ly;
    auto place = [&](double item_width) {
        if (lx + item_width > width - 10 && lx > 10) {
            lx = 10;
            row_y += 20;
        }
        const double x = lx;
        lx += item_width + 18;
        return x;
    };
    for (int c = 3; c >= 0; --c) {
        const double x = place(19 + 6.3 * std::string(region_name[c]).size());
        s << "<rect x=\"" << num(x) << "\" y=\"" << num(row_y) << "\" width=\"14\" height=\"14\" fill=\"" << region_fill[c]
          << "\" stroke=\"#555\" stroke-width=\"0.5\"/>\n";
        s << "<text x=\"" << num(x + 19) << "\" y=\"" << num(row_y + 11) << "\">" << region_name[c] << "</text>\n";
    }
    lx = 10;
    row_y += 22;
    for (BoundaryKind k : {BoundaryKind::RingHopf, BoundaryKind::PlantHopf, BoundaryKind::LowFrequency, BoundaryKind::Peak}) {
        const Style st = curve_style(k);
        const double x = place(31 + 6.3 * std::string(st.name).size());
        const double y = row_y + 7;
        s << "<line x1=\"" << num(x) << "\" y1=\"" << num(y) << "\" x2=\"" << num(x + 26) << "\" y2=\"" << num(y) << "\" stroke=\""
          << st.colour << "\" stroke-width=\"" << st.width << "\"";
        if (*st.dash) s << " stroke-dasharray=\"" << st.dash << "\"";
        s << "/>\n<text x=\"" << num(x + 31) << "\" y=\"" << num(y + 4) << "\">" << esc(st.name) << "</text>\n";
    }
    s << "</g>\n</svg>\n";
    return s.str();
}

namespace {
const char* palette[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2",
                         "#7f7f7f", "#bcbd22", "#17becf", "#393b79", "#637939", "#8c6d31", "#843c39"};
}  // namespace

std::string render_line_plots_svg(const std::vector<PlotPanel>& panels, const PlotOptions& o) {
    if (panels.empty()) throw std::invalid_argument("a plot needs at least one panel");
    const int cols = std::max(1, std::min<int>(o.columns, static_cast<int>(panels.size())));
    const int rows = (static_cast<int>(panels.size()) + cols - 1) / cols;
    const double ml = 62, mr = 16, mt = 34, mb = 48;
    const double cw = o.panel_width + ml + mr, ch = o.panel_height + mt + mb;
    const double header = o.title.empty() ? 10 : 34;
    const double width = cols * cw + 10;
    // legend entries: the series names of the first panel
    std::vector<std::pair<std::string, std::string>> entries;
    std::vector<bool> dashed_entries;
    if (o.legend) {
        std::size_t i = 0;
        for (const auto& sr : panels.front().series) {
            entries.emplace_back(sr.name, sr.colour.empty() ? palette[i % 14] : sr.colour);
            dashed_entries.push_back(sr.dashed);
            ++i;
        }
    }
    // one slot per entry, wide enough for the longest name (11 px text: about 6.5 px a character)
    std::size_t longest = 0;
    for (const auto& e : entries) longest = std::max(longest, e.first.size());
    const double slot = std::max(150.0, 29.0 + 6.5 * static_cast<double>(longest) + 14.0);
    const int per_row = std::max(1, static_cast<int>((width - 20) / slot));
    const double legend_h = entries.empty() ? 10 : 20.0 * ((entries.size() + per_row - 1) / per_row) + 12;
    const double note_h = o.note.empty() ? 0 : 20;
    const double height = header + rows * ch + legend_h + note_h;
    std::ostringstream s;
    svg_preamble(s, width, height, o.title);
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
        // a range below rounding noise of its values is flat (else the tick step underflows
        // the values' spacing and the tick loops never end)
        auto flat = [](double lo, double hi) { return !(hi - lo > 1e-9 * std::max({1.0, std::abs(lo), std::abs(hi)})); };
        if (flat(x0, x1)) { x0 -= 0.5; x1 += 0.5; }
        if (flat(y0, y1)) { y0 -= 0.5; y1 += 0.5; }
        const double pad = 0.04 * (y1 - y0);
        y0 -= pad;
        y1 += pad;
        const double sx = nice_step(x1 - x0), sy = nice_step(y1 - y0);
        x0 = std::floor(x0 / sx) * sx; x1 = std::ceil(x1 / sx) * sx;
        y0 = std::floor(y0 / sy) * sy; y1 = std::ceil(y1 / sy) * sy;
        const double ox = (pi % cols) * cw + ml + 5, oy = header + (pi / cols) * ch + mt;
        const double pw = o.panel_width, ph = o.panel_height;
        auto X = [&](double x) { return ox + (x - x0) / (x1 - x0) * pw; };
        auto Y = [&](double y) { return oy + ph - (y - y0) / (y1 - y0) * ph; };
        const std::string id = "plot" + std::to_string(pi + 1);
        s << "<g id=\"" << id << "\">\n";
        s << "<text id=\"" << id << "-title\" x=\"" << num(ox + pw / 2) << "\" y=\"" << num(oy - 10) << "\" text-anchor=\"middle\" font-size=\"12\">"
          << esc(p.title) << "</text>\n";
        s << "<g id=\"" << id << "-axes\" font-size=\"10\">\n";
        s << "<rect x=\"" << num(ox) << "\" y=\"" << num(oy) << "\" width=\"" << num(pw) << "\" height=\"" << num(ph)
          << "\" fill=\"none\" stroke=\"#000\"/>\n";
        for (int i = 0; i <= 1000 && x0 + i * sx <= x1 + 1e-9 * sx; ++i) {
            const double t = x0 + i * sx;
            s << "<line x1=\"" << num(X(t)) << "\" y1=\"" << num(oy) << "\" x2=\"" << num(X(t)) << "\" y2=\"" << num(oy + ph)
              << "\" stroke=\"#e5e5e5\"/>\n";
            s << "<text x=\"" << num(X(t)) << "\" y=\"" << num(oy + ph + 15) << "\" text-anchor=\"middle\">" << tick_text(t, sx) << "</text>\n";
        }
        for (int i = 0; i <= 1000 && y0 + i * sy <= y1 + 1e-9 * sy; ++i) {
            const double t = y0 + i * sy;
            s << "<line x1=\"" << num(ox) << "\" y1=\"" << num(Y(t)) << "\" x2=\"" << num(ox + pw) << "\" y2=\"" << num(Y(t))
              << "\" stroke=\"#e5e5e5\"/>\n";
            s << "<text x=\"" << num(ox - 6) << "\" y=\"" << num(Y(t) + 3.5) << "\" text-anchor=\"end\">" << tick_text(t, sy) << "</text>\n";
        }
        s << "<text x=\"" << num(ox + pw / 2) << "\" y=\"" << num(oy + ph + 34) << "\" text-anchor=\"middle\" font-size=\"12\">" << esc(p.x_label)
          << "</text>\n";
        s << "<text transform=\"translate(" << num(ox - 44) << "," << num(oy + ph / 2) << ") rotate(-90)\" text-anchor=\"middle\" font-size=\"12\">"
          << esc(p.y_label) << "</text>\n";
        s << "</g>\n";
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
    if (!entries.empty()) {
        const double ly = header + rows * ch + 4;
        s << "<g id=\"legend\" font-size=\"11\">\n";
        for (std::size_t i = 0; i < entries.size(); ++i) {
            const double x = 10 + (i % per_row) * slot, y = ly + (i / per_row) * 20;
            s << "<line x1=\"" << num(x) << "\" y1=\"" << num(y + 7) << "\" x2=\"" << num(x + 24) << "\" y2=\"" << num(y + 7)
              << "\" stroke=\"" << entries[i].second << "\" stroke-width=\"2\"" << (dashed_entries[i] ? " stroke-dasharray=\"5,3\"" : "")
              << "/>\n<text x=\"" << num(x + 29) << "\" y=\"" << num(y + 11) << "\">" << esc(entries[i].first) << "</text>\n";
        }
        s << "</g>\n";
    }
    if (!o.note.empty()) {
        s << "<text id=\"note\" x=\"10\" y=\"" << num(height - 6) << "\" font-size=\"11\">" << esc(o.note) << "</text>\n";
    }
    s << "</svg>\n";
    return s.str();
}

void write_file_atomic(const std::string& path, const std::string& text) {
    const std::string tmp = path + ".tmp";
    {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        if (!out) throw WriteError("cannot write " + path + ": the folder does not exist or is not writable");
        out << text;
        out.flush();
        if (!out) {
            std::remove(tmp.c_str());
            throw WriteError("cannot write " + path);
        }
    }
    if (std::rename(tmp.c_str(), path.c_str()) != 0) {
        std::remove(tmp.c_str());
        throw WriteError("cannot write " + path);
    }
}

void write_files_atomic(const std::vector<std::pair<std::string, std::string>>& files) {
    std::vector<std::string> written;
    try {
        for (const auto& [path, text] : files) {
            write_file_atomic(path + ".part", text);
            written.push_back(path + ".part");
        }
    } catch (...) {
        for (const auto& w : written) std::remove(w.c_str());
        throw;
    }
    // a rename can still fail (e.g. the target is a folder): then no .part file is left and none
    // of the files of this call remains, so that the set is never half new
    for (std::size_t i = 0; i < files.size(); ++i) {
        const std::string& path = files[i].first;
        if (std::rename((path + ".part").c_str(), path.c_str()) != 0) {
            for (std::size_t j = 0; j < files.size(); ++j) std::remove((files[j].first + (j < i ? "" : ".part")).c_str());
            throw WriteError("cannot write " + path);
        }
    }
}

}  // namespace ddemap
