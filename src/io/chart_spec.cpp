#include "ddemap/io/chart_spec.hpp"

#include <algorithm>

#include "core/internal/text.hpp"
#include "ddemap/io/cars.hpp"
#include "ddemap/io/csv.hpp"
#include "io/internal/toml_fields.hpp"

#include <chrono>
#include <cmath>
#include <iomanip>
#include <optional>
#include <sstream>
#include <stdexcept>

#include <toml++/toml.h>

namespace ddemap {

namespace {

std::string where(const std::string& source, const toml::node& n) { return detail::toml_where(source, n); }

double number(const std::string& source, const toml::node& n, const std::string& key) { return detail::toml_number(source, n, key); }

std::optional<int64_t> integer_in(const toml::node& n, int64_t lo, int64_t hi) { return detail::toml_integer_in(n, lo, hi); }

std::string short_number(double v) {  // 4 significant digits: a title, not data
    std::ostringstream os;
    os << std::setprecision(4) << v;
    return os.str();
}

Axis read_axis(const std::string& source, const toml::table& root, const char* key) {
    const toml::node* n = root.get(key);
    if (!n || !n->is_table()) throw std::invalid_argument(source + ": [" + std::string(key) + "] table missing: expected name, lo, hi, count");
    const toml::table& t = *n->as_table();
    for (const auto& [k, v] : t) {  // a misspelt key (cout = 50) is an error, never ignored
        const std::string ks(k.str());
        if (ks != "name" && ks != "lo" && ks != "hi" && ks != "count")
            throw std::invalid_argument(where(source, v) + ": " + key + ": unknown key " + detail::quoted(ks) + ": expected name, lo, hi, count");
    }
    Axis a;
    const toml::node* name = t.get("name");
    if (!name || !name->is_string()) throw std::invalid_argument(where(source, *n) + ": " + key + ".name: expected a parameter name");
    a.name = *name->value<std::string>();
    for (const char* k : {"lo", "hi", "count"})
        if (!t.get(k)) throw std::invalid_argument(where(source, *n) + ": " + key + "." + k + " missing");
    a.lo = number(source, *t.get("lo"), std::string(key) + ".lo");
    a.hi = number(source, *t.get("hi"), std::string(key) + ".hi");
    const auto c = integer_in(*t.get("count"), 2, 100000);
    if (!c || !(a.lo < a.hi)) {
        throw std::invalid_argument(where(source, *n) + ": " + key + ": expected lo < hi and an integer count from 2 to 100000");
    }
    a.count = static_cast<int>(*c);
    return a;
}

}  // namespace

SweepSpec panel_sweep(const ChartSpec& spec, std::size_t panel) {
    SweepSpec s;
    s.peak = spec.peak;
    s.model = spec.model;
    s.fixed = spec.fixed;
    for (const auto& [k, v] : spec.panels.at(panel).parameters) s.fixed[k] = v;
    s.x = spec.x;
    s.y = spec.y;
    s.cars = spec.cars;
    // every mode's ring curve needs every mode's root; the envelope is seeded from the winding sweep
    if (spec.boundaries && s.cars > 0 && resolve_ring_curves(spec.ring_curves, s) == RingCurves::All) s.ring_method = "modes";
    return s;
}

std::vector<PanelSpec> vehicle_panels(const std::vector<CalibratedVehicle>& vehicles) {
    // one panel per distinct (tau, th): the (k1, k2) chart of OVRV depends on nothing else
    std::vector<PanelSpec> panels;
    std::vector<std::pair<double, double>> keys;
    std::vector<std::vector<const CalibratedVehicle*>> members;
    for (const auto& v : vehicles) {
        const std::pair<double, double> key{v.parameters.at("tau"), v.parameters.at("th")};
        const auto it = std::find(keys.begin(), keys.end(), key);
        if (it == keys.end()) {
            keys.push_back(key);
            members.push_back({&v});
        } else {
            members[static_cast<std::size_t>(it - keys.begin())].push_back(&v);
        }
    }
    for (std::size_t g = 0; g < keys.size(); ++g) {
        PanelSpec p;
        const std::string where = parameter_symbol("tau") + " = " + short_number(keys[g].first) + " s, " + parameter_symbol("th") + " = " +
                                  short_number(keys[g].second) + " s";
        p.title = members[g].size() == 1 ? members[g].front()->name + ": " + where : where;
        p.parameters["tau"] = keys[g].first;
        p.parameters["th"] = keys[g].second;
        if (members[g].front()->parameters.count("eta")) p.parameters["eta"] = members[g].front()->parameters.at("eta");  // no effect on the chart
        for (const CalibratedVehicle* v : members[g]) {
            ChartMarker m;
            m.x = v->parameters.at("k1");
            m.y = v->parameters.at("k2");
            m.label = v->name;
            if (v->has_covariance) {  // the (k1, k2) block of the calibration's covariance
                m.has_ellipse = true;
                m.cov_xx = v->covariance(0, 0);
                m.cov_xy = v->covariance(0, 1);
                m.cov_yy = v->covariance(1, 1);
            }
            p.markers.push_back(m);
        }
        panels.push_back(p);
    }
    return panels;
}

ChartSpec parse_chart_spec(const std::string& text, const std::string& source) {
    toml::table root;
    try {
        root = toml::parse(text, source);
    } catch (const toml::parse_error& e) {
        std::ostringstream os;
        os << source << ":" << e.source().begin.line << ": " << detail::escaped(std::string(e.description()));
        throw std::invalid_argument(os.str());
    }
    ChartSpec spec;
    static const char* known[] = {"title", "model", "ring", "fixed", "x", "y", "columns", "panel_width",
                                  "panel_height", "boundaries", "ring_curves", "panel", "vehicles", "peak"};
    for (const auto& [k, v] : root) {
        const std::string key(k.str());
        if (std::find_if(std::begin(known), std::end(known), [&](const char* s) { return key == s; }) == std::end(known)) {
            throw std::invalid_argument(where(source, v) + ": unknown key " + detail::quoted(key));
        }
    }
    if (auto t = root["title"].value<std::string>()) spec.title = *t;
    if (auto m = root["model"].value<std::string>()) spec.model = *m;
    if (const toml::node* r = root.get("ring")) {
        if (auto s = r->value<std::string>(); s && *s == "inf") {
            spec.cars = 0;
        } else if (auto n = integer_in(*r, 2, 1000000000)) {
            spec.cars = static_cast<int>(*n);
        } else {
            throw std::invalid_argument(where(source, *r) + ": ring: expected an integer N from 2 to 1e9 or \"inf\"");
        }
    }
    if (const toml::node* f = root.get("fixed")) {
        if (!f->is_table()) throw std::invalid_argument(where(source, *f) + ": fixed: expected a table of parameters");
        for (const auto& [k, v] : *f->as_table()) spec.fixed[std::string(k.str())] = number(source, v, "fixed." + std::string(k.str()));
    }
    spec.x = read_axis(source, root, "x");
    spec.y = read_axis(source, root, "y");
    if (const toml::node* c = root.get("columns")) {
        const auto v = integer_in(*c, 1, 64);
        if (!v) throw std::invalid_argument(where(source, *c) + ": columns: expected an integer from 1 to 64");
        spec.columns = static_cast<int>(*v);
    }
    // panel sizes in px: a finite figure (never width="inf" or a negative width in the SVG)
    auto size = [&](const char* key, double& out) {
        if (const toml::node* n = root.get(key)) {
            out = number(source, *n, key);
            if (!(out >= 40.0 && out <= 4000.0)) {
                throw std::invalid_argument(where(source, *n) + ": " + key + " = " + short_number(out) + ": expected 40 to 4000 (px)");
            }
        }
    };
    size("panel_width", spec.panel_width);
    size("panel_height", spec.panel_height);
    if (auto b = root["boundaries"].value<bool>()) spec.boundaries = *b;
    if (const toml::node* pk = root.get("peak")) {
        const auto v = pk->value<bool>();
        if (!v) throw std::invalid_argument(where(source, *pk) + ": peak: expected true or false");
        spec.peak = *v;
    }
    if (const toml::node* rc = root.get("ring_curves")) {
        const auto v = rc->value<std::string>();
        if (!v || (*v != "all" && *v != "envelope" && *v != "auto"))
            throw std::invalid_argument(where(source, *rc) + ": ring_curves: expected \"all\", \"envelope\" or \"auto\"");
        spec.ring_curves = parse_ring_curves(*v);
    }
    if (const toml::node* v = root.get("vehicles")) {
        // "paper" (the built-in table) or a car list (io/cars.hpp), files found beside the spec
        const auto list = v->value<std::string>();
        if (!list || list->empty())
            throw std::invalid_argument(where(source, *v) + ": vehicles: expected \"paper\" (the built-in calibration table) or a car list "
                                        "(\"mycars.csv\", \"fits.json\", \"A_min,mycars.csv:Sedan\", ...)");
        std::vector<CalibratedVehicle> cars;
        if (*list == "paper") {
            cars = paper_calibration_table();
        } else {
            const auto slash = source.rfind('/');
            try {
                cars = distinct_cars(read_cars(*list, kMaxCars, slash == std::string::npos ? std::string() : source.substr(0, slash)));
                require_ovrv(cars, "a chart of vehicles");
            } catch (const std::invalid_argument& e) {
                throw std::invalid_argument(where(source, *v) + ": vehicles: " + e.what());
            }
        }
        spec.panels = vehicle_panels(cars);
    }
    if (const toml::node* ps = root.get("panel")) {
        const toml::array* arr = ps->as_array();
        if (!arr) throw std::invalid_argument(where(source, *ps) + ": panel: expected [[panel]] tables");
        for (const auto& pn : *arr) {
            const toml::table* pt = pn.as_table();
            if (!pt) throw std::invalid_argument(where(source, pn) + ": panel: expected a table");
            PanelSpec p;
            for (const auto& [k, v] : *pt) {
                const std::string key(k.str());
                if (key == "title") {
                    p.title = v.value<std::string>().value_or("");
                } else if (key == "marker") {
                    const toml::array* ms = v.as_array();
                    if (!ms) throw std::invalid_argument(where(source, v) + ": marker: expected [[panel.marker]] tables");
                    for (const auto& mn : *ms) {
                        const toml::table* mt = mn.as_table();
                        if (!mt || !mt->get(spec.x.name) || !mt->get(spec.y.name)) {
                            throw std::invalid_argument(where(source, mn) + ": marker: expected " + spec.x.name + " and " + spec.y.name);
                        }
                        ChartMarker m;
                        m.x = number(source, *mt->get(spec.x.name), "marker." + spec.x.name);
                        m.y = number(source, *mt->get(spec.y.name), "marker." + spec.y.name);
                        m.label = (*mt)["label"].value<std::string>().value_or("");
                        p.markers.push_back(m);
                    }
                } else {
                    p.parameters[key] = number(source, v, "panel." + key);
                }
            }
            spec.panels.push_back(p);
        }
    }
    if (spec.panels.empty()) spec.panels.push_back(PanelSpec{});
    // validate every panel's model at the window corners now, with the source named
    for (std::size_t i = 0; i < spec.panels.size(); ++i) {
        try {
            panel_sweep(spec, i).validate();
        } catch (const std::invalid_argument& e) {
            throw std::invalid_argument(source + ": panel " + std::to_string(i + 1) + ": " + e.what());
        }
    }
    return spec;
}

RenderedChart render_chart(const ChartSpec& spec, const ExecutionPolicy& policy) {
    ExecutionPolicy per_panel = policy;
    per_panel.progress = nullptr;
    const auto t0 = std::chrono::steady_clock::now();
    RenderedChart out;
    const std::size_t n = spec.panels.size();
    out.specs.resize(n);
    out.sweeps.resize(n);
    out.boundaries.resize(n);
    for (std::size_t i = 0; i < n; ++i) {  // every panel checked (the computable range at its corners) before any work
        out.specs[i] = panel_sweep(spec, i);  // the ring method the boundaries need
        out.specs[i].validate();
    }
    for (std::size_t i = 0; i < n; ++i) {
        // the panel's rows reported as a share of all panels' rows (each panel has the same grid)
        if (policy.progress)
            per_panel.progress = [&policy, i, n](long done, long total) {
                policy.progress(static_cast<long>(i) * total + done, static_cast<long>(n) * total);
            };
        out.sweeps[i] = run_sweep(out.specs[i], per_panel);
        BoundaryOptions bo;
        bo.ring_curves = spec.ring_curves;
        if (spec.boundaries) out.boundaries[i] = trace_boundaries(out.sweeps[i], bo);
    }
    std::vector<ChartPanel> panels(n);
    for (std::size_t i = 0; i < n; ++i) {
        panels[i].sweep = &out.sweeps[i];
        panels[i].boundaries = spec.boundaries ? &out.boundaries[i] : nullptr;
        panels[i].markers = spec.panels[i].markers;
        std::string title = spec.panels[i].title;
        if (title.empty()) {
            for (const auto& [k, v] : spec.panels[i].parameters) {
                std::string unit;
                for (const auto& ps : model_parameters(spec.model))
                    if (ps.name == k && ps.unit != "1") unit = " " + unit_text(ps.unit);
                title += (title.empty() ? "" : ", ") + parameter_symbol(k) + " = " + short_number(v) + unit;
            }
        }
        panels[i].title = title;
    }
    ChartOptions co;
    co.title = spec.title;
    co.columns = spec.columns;
    co.panel_width = spec.panel_width;
    co.panel_height = spec.panel_height;
    out.svg = render_chart_svg(panels, co);
    out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return out;
}

std::string sweep_chart_title(const SweepSpec& spec) {
    // parameter symbols with their units (k1 [1/s^2] -> "k₁ = 0.2 1/s²")
    std::string t = spec.model;
    for (const auto& [k, v] : spec.fixed) {
        std::string unit;
        for (const auto& ps : model_parameters(spec.model))
            if (ps.name == k && ps.unit != "1") unit = " " + unit_text(ps.unit);
        t += ", " + parameter_symbol(k) + " = " + detail::significant(v == 0.0 ? 0.0 : v, 4) + unit;
    }
    return t + ", N = " + (spec.cars == 0 ? std::string("inf") : std::to_string(spec.cars));
}

std::string sweep_chart_svg(const SweepSpec& spec, const SweepResult& sweep, const BoundarySet* boundaries, const std::vector<ChartMarker>& markers) {
    ChartOptions co;
    co.title = "Stability chart: " + sweep_chart_title(spec);
    co.columns = 1;
    co.panel_width = 520;
    co.panel_height = 440;
    ChartPanel panel;
    panel.title = sweep_chart_title(spec);
    panel.sweep = &sweep;
    panel.boundaries = boundaries;
    panel.markers = markers;
    return render_chart_svg({panel}, co);
}

std::vector<ChartMarker> car_markers(const std::vector<CalibratedVehicle>& cars, const SweepSpec& spec, std::vector<std::string>* notes) {
    static const char* fitted[] = {"k1", "k2", "th", "tau", "eta"};
    auto index = [](const std::string& name) {
        for (int i = 0; i < 5; ++i)
            if (name == fitted[i]) return i;
        return -1;
    };
    std::vector<ChartMarker> out;
    for (const CalibratedVehicle& car : cars) {
        if (car.model != spec.model)
            throw std::invalid_argument("car '" + car.name + "' has model " + car.model + ": expected cars of the chart's model " + spec.model);
        for (const std::string& axis : {spec.x.name, spec.y.name})
            if (!car.parameters.count(axis)) throw std::invalid_argument("car '" + car.name + "' has no value of " + axis);
        ChartMarker m;
        m.x = car.parameters.at(spec.x.name);
        m.y = car.parameters.at(spec.y.name);
        m.label = car.name;
        const int ix = index(spec.x.name), iy = index(spec.y.name);
        if (car.has_covariance && ix >= 0 && iy >= 0) {
            m.has_ellipse = true;
            m.cov_xx = car.covariance(ix, ix);
            m.cov_xy = car.covariance(ix, iy);
            m.cov_yy = car.covariance(iy, iy);
        }
        std::string differ;
        for (const auto& [name, value] : spec.fixed) {
            if (!car.parameters.count(name) || (spec.model == "ovrv" && name == "eta")) continue;  // eta moves no boundary of OVRV's chart
            const double v = car.parameters.at(name);
            if (std::abs(v - value) > 1e-9 * std::max(std::abs(v), std::abs(value)))
                differ += (differ.empty() ? "" : ", ") + name + " = " + detail::significant(v, 6) + " (the chart's " + detail::significant(value, 6) + ")";
        }
        if (!differ.empty() && notes)
            notes->push_back(car.name + " has " + differ + ": its marker shows its " + spec.x.name + " and " + spec.y.name + " on a chart that is not its own");
        out.push_back(m);
    }
    return out;
}

std::string design_chart_svg(const DesignResult& d, const std::string& car_name, int cars, const Eigen::Matrix<double, 5, 5>* covariance,
                             const ExecutionPolicy& policy) {
    if (!d.initial.count("k1") || !d.initial.count("k2") || !d.parameters.count("k1") || !d.parameters.count("k2")) return "";
    const double x0 = d.initial.at("k1"), y0 = d.initial.at("k2"), x1 = d.parameters.at("k1"), y1 = d.parameters.at("k2");
    // the ellipse's extent along each axis, sqrt(5.991 C_ii)
    const double ex = covariance ? std::sqrt(5.991464547107979 * std::max(0.0, (*covariance)(0, 0))) : 0.0;
    const double ey = covariance ? std::sqrt(5.991464547107979 * std::max(0.0, (*covariance)(1, 1))) : 0.0;
    // the path of the run that gave the result (its end at the designed gains), in (k1, k2)
    std::vector<std::pair<double, double>> path;
    double nearest = std::numeric_limits<double>::infinity();
    for (const DesignStart& st : d.starts) {
        if (!st.end.count("k1") || !st.end.count("k2")) continue;
        const double e = std::hypot((st.end.at("k1") - x1) / std::max(std::abs(x1), 1e-300), (st.end.at("k2") - y1) / std::max(std::abs(y1), 1e-300));
        if (e < nearest) {
            nearest = e;
            path.clear();
            for (const ParameterMap& q : st.path)
                if (q.count("k1") && q.count("k2")) path.emplace_back(q.at("k1"), q.at("k2"));
        }
    }
    if (!(nearest <= 1e-9)) path.clear();  // no run ends there (a later stage moved it): no path drawn
    // the window holds the car, the design, the ellipse and the path
    double px_lo = std::min(x0, x1), px_hi = std::max(x0, x1), py_lo = std::min(y0, y1), py_hi = std::max(y0, y1);
    for (const auto& q : path) {
        px_lo = std::min(px_lo, q.first);
        px_hi = std::max(px_hi, q.first);
        py_lo = std::min(py_lo, q.second);
        py_hi = std::max(py_hi, q.second);
    }
    auto window = [](double a, double b, double e) {
        double lo = std::min(a, b) - e, hi = std::max(a, b) + e;
        const double span = std::max(hi - lo, 0.1 * std::max(std::abs(a), std::abs(b)));
        lo -= 0.25 * span;
        hi += 0.25 * span;
        lo = std::max(lo, 0.02 * hi);  // gains above 0 (the charts' convention)
        return std::pair<double, double>{lo, hi};
    };
    // (pairs, not structured bindings: clang refuses to capture those in the lambda below)
    const std::pair<double, double> xr = window(px_lo, px_hi, ex), yr = window(py_lo, py_hi, ey);
    auto spec_at = [&](const ParameterMap& params) {
        SweepSpec s;
        s.model = d.model;
        // (OVRV's chart depends on neither eta nor the speed: left out of the title)
        for (const auto& [k, v] : params)
            if (k != "k1" && k != "k2" && !(d.model == "ovrv" && (k == "eta" || k == "speed"))) s.fixed[k] = v;
        s.x = Axis{"k1", xr.first, xr.second, 81};
        s.y = Axis{"k2", yr.first, yr.second, 81};
        s.cars = cars;
        return s;
    };
    bool others_changed = false;
    for (const auto& [k, v] : d.initial)
        if (k != "k1" && k != "k2" && d.parameters.count(k) && d.parameters.at(k) != v) others_changed = true;
    ChartMarker car;
    car.x = x0;
    car.y = y0;
    car.label = car_name;
    if (covariance) {
        car.has_ellipse = true;
        car.cov_xx = (*covariance)(0, 0);
        car.cov_xy = (*covariance)(0, 1);
        car.cov_yy = (*covariance)(1, 1);
    }
    ChartMarker designed;
    designed.x = x1;
    designed.y = y1;
    designed.label = car_name + ", designed";
    std::vector<SweepSpec> specs = {spec_at(d.initial)};
    if (others_changed) specs.push_back(spec_at(d.parameters));
    std::vector<SweepResult> sweeps;
    std::vector<BoundarySet> bounds;
    for (const SweepSpec& s : specs) {
        sweeps.push_back(run_sweep(s, policy));
        bounds.push_back(trace_boundaries(sweeps.back(), BoundaryOptions{}));
    }
    std::vector<ChartPanel> panels;
    for (std::size_t i = 0; i < specs.size(); ++i) {
        ChartPanel p;
        p.title = (others_changed ? (i == 0 ? "the car's chart: " : "the design's chart: ") : std::string()) + sweep_chart_title(specs[i]);
        p.sweep = &sweeps[i];
        p.boundaries = &bounds[i];
        if (i == 0) p.markers.push_back(car);
        if (i == 0 && !others_changed) {
            p.markers.push_back(designed);
            p.path = path;
        }
        if (i == 1) {
            ChartMarker own = car;
            own.label = car_name + " (its k1, k2)";
            own.has_ellipse = false;
            p.markers = {own, designed};
        }
        panels.push_back(p);
    }
    ChartOptions co;
    co.title = "Gain design for " + car_name + " (" + d.objective + "): from its gains to the designed ones";
    co.columns = static_cast<int>(panels.size());
    co.panel_width = 420;
    co.panel_height = 360;
    return render_chart_svg(panels, co);
}

long chart_uncertified(const RenderedChart& chart) {
    long n = 0;
    for (const SweepResult& sw : chart.sweeps) n += sw.uncertified;
    return n;
}

std::string chart_message(const RenderedChart& chart) {
    std::size_t points = 0;
    for (std::size_t k = 0; k < chart.sweeps.size(); ++k) {
        const SweepResult& sw = chart.sweeps[k];
        if (sw.uncertified > 0)
            return "panel " + std::to_string(k + 1) + ": " + std::to_string(sw.uncertified) + (sw.uncertified == 1 ? " point has" : " points have") +
                   " no certificate even after collocation (see the 'certified' column of its grid CSV)";
        points += sw.points.size();
    }
    return "every one of the " + std::to_string(points) + " grid points of the " + std::to_string(chart.sweeps.size()) +
           (chart.sweeps.size() == 1 ? " panel" : " panels") +
           " certified: no root of the plant or of the ring lies right of the abscissa reported (argument principle)";
}

std::vector<std::pair<std::string, std::string>> chart_files(const RenderedChart& chart, const std::string& prefix) {
    std::vector<std::pair<std::string, std::string>> files{{prefix + ".svg", chart.svg}};
    for (std::size_t i = 0; i < chart.sweeps.size(); ++i) {
        const std::string base = prefix + "-panel" + std::to_string(i + 1);
        files.emplace_back(base + ".csv", sweep_csv(chart.sweeps[i]));
        files.emplace_back(base + "-boundaries.csv", boundary_csv(chart.specs[i], chart.boundaries[i]));
    }
    return files;
}

}  // namespace ddemap
