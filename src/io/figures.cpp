#include "ddemap/io/figures.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "ddemap/io/svg.hpp"

namespace ddemap {

namespace {
std::string rounded(double v, int digits) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*g", digits, v == 0.0 ? 0.0 : v);
    return buf;
}
}  // namespace

std::string simulation_svg(const SimResult& r, const std::string& lead) {
    // Speeds and gaps of every car. A car that collides ends at its collision (a red cross): the
    // simulation may go on (--on-event continue) but its values after the collision are not
    // physical. Events are named in the note under the legend, never as labels in the plot
    // (labels of events close in time would overlap).
    PlotPanel speeds{"Speeds", "time [s]", "speed [m/s]", {}, {}};
    PlotPanel gaps{"Gaps to the car ahead", "time [s]", "gap [m]", {}, {}};
    speeds.y_floor = 0.0;
    speeds.y_from_floor = true;  // speeds from 0 m/s: a drop is seen against the whole speed
    gaps.y_floor = 0.0;
    std::vector<double> end(r.speed.size(), std::numeric_limits<double>::infinity());
    for (const auto& ev : r.events)
        if (ev.type == "collision" && ev.car > 0 && static_cast<std::size_t>(ev.car) < end.size())
            end[static_cast<std::size_t>(ev.car)] = std::min(end[static_cast<std::size_t>(ev.car)], ev.time);
    for (std::size_t c = 0; c < r.speed.size(); ++c) {
        const std::string name = c == 0 ? "lead" : "car " + std::to_string(c) + " (" + r.cars[c - 1].name + ")";
        const std::string colour = c == 0 ? "#000000" : plot_colour(c - 1);
        PlotSeries v{name, {}, {}, colour, c == 0}, g{name, {}, {}, colour, false};
        for (std::size_t k = 0; k < r.time.size() && k < r.speed[c].size(); ++k) {
            if (r.time[k] > end[c]) break;
            v.x.push_back(r.time[k]);
            v.y.push_back(r.speed[c][k]);
            if (c > 0 && k < r.gap[c].size()) {
                g.x.push_back(r.time[k]);
                g.y.push_back(r.gap[c][k]);
            }
        }
        speeds.series.push_back(v);
        if (c > 0) gaps.series.push_back(g);
    }
    std::vector<std::string> collided, disengaged;
    for (const auto& ev : r.events) {
        if (ev.car > 0 && static_cast<std::size_t>(ev.car) < end.size() && ev.time > end[static_cast<std::size_t>(ev.car)]) continue;  // after its collision
        const bool collision = ev.type == "collision";
        const std::string colour = collision ? "#d62728" : "#000000";
        speeds.markers.push_back({ev.time, ev.speed, colour, ""});
        gaps.markers.push_back({ev.time, ev.gap, colour, ""});
        char text[64];
        std::snprintf(text, sizeof text, "car %d at %.1f s", ev.car, ev.time);
        (collision ? collided : disengaged).push_back(text);
    }
    PlotOptions po;
    po.title = "Platoon behind the '" + lead + "' lead profile";
    po.columns = 1;
    po.panel_width = 760;
    po.panel_height = 300;
    const auto listed = [](const std::vector<std::string>& items) {
        std::string s;
        for (std::size_t i = 0; i < items.size() && i < 4; ++i) s += (i ? ", " : "") + items[i];
        if (items.size() > 4) s += " and " + std::to_string(items.size() - 4) + " more";
        return s;
    };
    if (!collided.empty()) po.note = "red x: collision (" + listed(collided) + "), the car's lines end there";
    if (!disengaged.empty()) po.note += (po.note.empty() ? "" : "; ") + std::string("black x: ACC disengages (") + listed(disengaged) + ")";
    return render_line_plots_svg({speeds, gaps}, po);
}

std::string growth_svg(const std::vector<GrowthResult>& g, const std::string& lead) {
    PlotPanel gap{"Minimum gap", "position in the platoon", "minimum gap [m]", {}, {}};
    gap.y_floor = 0.0;
    PlotPanel amp{"Disturbance amplification", "position in the platoon", "speed drop / lead's drop [1]", {}, {}};
    for (const auto& r : g) {
        PlotSeries a{r.name, {}, {}, "", r.name.find("max") != std::string::npos};
        PlotSeries b = a;
        for (std::size_t i = 0; i < r.amplification.size(); ++i) {
            a.x.push_back(i + 1.0);
            a.y.push_back(r.min_gap[i]);
            b.x.push_back(i + 1.0);
            b.y.push_back(r.amplification[i]);
        }
        if (r.failed_at) {
            const std::string colour = r.failure == "collision" ? "#d62728" : "#000000";
            a.x.push_back(r.failed_at);
            a.y.push_back(r.failure_gap);
            b.x.push_back(r.failed_at);
            b.y.push_back(r.failure_amplification);
            gap.markers.push_back({double(r.failed_at), r.failure_gap, colour, ""});
            amp.markers.push_back({double(r.failed_at), r.failure_amplification, colour, ""});
        }
        gap.series.push_back(a);
        amp.series.push_back(b);
    }
    PlotOptions o;
    o.title = "Disturbance growth behind the '" + lead + "' lead profile (calibrated OVRV platoons)";
    // the note names only the marks the figure shows
    bool disengage = false, collision = false, dashed = false;
    for (const auto& r : g) {
        disengage = disengage || (r.failed_at && r.failure != "collision");
        collision = collision || (r.failed_at && r.failure == "collision");
        dashed = dashed || r.name.find("max") != std::string::npos;
    }
    std::vector<std::string> notes;
    if (disengage) notes.push_back("black x: ACC disengages (speed below the minimum ACC speed)");
    if (collision) notes.push_back("red x: gap reaches zero (collision)");
    if (dashed) notes.push_back("dashed: max setting");
    for (std::size_t i = 0; i < notes.size(); ++i) o.note += (i ? "; " : "") + notes[i];
    return render_line_plots_svg({gap, amp}, o);
}

std::string calibration_svg(const std::vector<std::string>& names, const std::vector<Trace>& traces,
                            const std::vector<CalibrationResult>& fits) {
    std::vector<PlotPanel> panels;
    for (std::size_t i = 0; i < fits.size() && i < traces.size(); ++i) {
        const Trace& t = traces[i];
        const std::string name = i < names.size() ? names[i] : t.source;
        PlotPanel sp{name + ": speed", "time [s]", "speed [m/s]", {}, {}};
        sp.series.push_back({"lead (measured)", t.t, t.lead, "#7f7f7f", true});
        sp.series.push_back({"follower (measured)", t.t, t.speed, "#000000", false});
        sp.series.push_back({"follower (model)", t.t, fits[i].sim_speed, "#d62728", false});
        PlotPanel gp{name + ": gap", "time [s]", "gap [m]", {}, {}};
        gp.series.push_back({"follower (measured)", t.t, t.gap, "#000000", false});
        gp.series.push_back({"follower (model)", t.t, fits[i].sim_gap, "#d62728", false});
        panels.push_back(sp);
        panels.push_back(gp);
    }
    PlotOptions po;
    po.title = "Calibrated OVRV: measured and simulated follower";
    po.columns = 2;
    return render_line_plots_svg(panels, po);
}

std::string mix_svg(const std::vector<MixPoint>& pts, const MixOptions& o, const std::string& x_label,
                    const std::string& y_label) {
    PlotSeries spread{"evenly spread", {}, {}, "#1f77b4", false}, lo{"min over arrangements", {}, {}, "#7f7f7f", true},
        hi{"max over arrangements", {}, {}, "#7f7f7f", true}, zero{"stability boundary", {}, {}, "#000000", true};
    for (const auto& pt : pts) {
        const double p = static_cast<double>(pt.x_cars) / o.cars;
        spread.x.push_back(p);
        spread.y.push_back(pt.abscissa);
        lo.x.push_back(p);
        lo.y.push_back(pt.abscissa_min);
        hi.x.push_back(p);
        hi.y.push_back(pt.abscissa_max);
    }
    zero.x = {0.0, 1.0};
    zero.y = {0.0, 0.0};
    PlotPanel panel{"Ring of " + std::to_string(o.cars) + " cars: X = " + x_label + ", Y = " + y_label, "fraction of X cars p = k / N",
                    "spectral abscissa [1/s] (trivial root excluded)", {spread}, {}};
    if (o.draws > 0) {
        panel.series.push_back(lo);
        panel.series.push_back(hi);
    }
    panel.series.push_back(zero);
    PlotOptions po;
    po.columns = 1;
    po.panel_width = 560.0;
    po.panel_height = 320.0;
    po.title = "Penetration-rate study (" +
               std::string(std::isnan(o.ring.length) ? "speed " + rounded(o.ring.speed, 4) + " m/s" : "length " + rounded(o.ring.length, 6) + " m") + ")";
    po.note = "above 0: the ring is unstable (a small disturbance grows)";
    return render_line_plots_svg({panel}, po);
}

ChartSpec classification_chart(const ChartSpec& base, const std::vector<CalibratedVehicle>& vehicles, int cars, const std::string& source) {
    ChartSpec spec = base;
    spec.panels = vehicle_panels(vehicles);
    spec.cars = cars;
    const std::string ring = cars == 0 ? std::string("an infinite ring") : "a ring of " + std::to_string(cars) + " cars";
    if (!source.empty()) {
        spec.title = "Vehicles of " + source + " on their own stability charts, " + ring;
        // the window: every car's (k1, k2) and its whole 95 % ellipse (extent sqrt(5.991 C_ii)),
        // within the domain its fit searched (its bounds; k1, k2 >= 0 without them); and where
        // the string-stable region's low-frequency edge c2 = 0 lies above a car at its k1 (for
        // OVRV k2 = (1 + k1 th (tau - th / 2)) / (th - tau) when th > tau) within three spans, up
        // to that edge, so that the verdict can be read off; widened by 12 % of the span on each
        // side and kept above 2 % of its upper end (k1, k2 > 0)
        double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
        for (const auto& v : vehicles) {
            const double k1 = v.parameters.at("k1"), k2 = v.parameters.at("k2");
            x0 = std::min(x0, k1);
            x1 = std::max(x1, k1);
            y0 = std::min(y0, k2);
            y1 = std::max(y1, k2);
            if (!v.has_covariance) continue;
            auto within = [&](const char* name, double lo, double hi) {
                double a = 0.0, b = std::numeric_limits<double>::infinity();
                if (const BoundedParameter* bp = find_bound(v.bounds, name)) {
                    a = bp->lower;
                    b = bp->upper;
                }
                return std::pair<double, double>{std::max(lo, a), std::min(hi, b)};
            };
            const double ex = std::sqrt(5.991464547107979 * std::max(0.0, v.covariance(0, 0)));
            const double ey = std::sqrt(5.991464547107979 * std::max(0.0, v.covariance(1, 1)));
            const auto [ex0, ex1] = within("k1", k1 - ex, k1 + ex);
            const auto [ey0, ey1] = within("k2", k2 - ey, k2 + ey);
            x0 = std::min(x0, ex0);
            x1 = std::max(x1, ex1);
            y0 = std::min(y0, ey0);
            y1 = std::max(y1, ey1);
        }
        const double span_y = std::max(y1 - y0, 0.05 * std::abs(y1));
        for (const auto& v : vehicles) {
            const double k1 = v.parameters.at("k1"), k2 = v.parameters.at("k2"), th = v.parameters.at("th"), tau = v.parameters.at("tau");
            if (!(th > tau)) continue;
            const double edge = (1.0 + k1 * th * (tau - 0.5 * th)) / (th - tau);
            if (edge > k2 && edge > y1 && edge <= y1 + 3.0 * span_y) y1 = edge;
        }
        // (but never above half the smallest car's value, so every car is inside)
        auto widen = [](double& lo, double& hi, double smallest) {
            const double span = hi - lo > 0.0 ? hi - lo : std::max(0.5 * std::abs(hi), 0.01);
            lo -= 0.12 * span;
            hi += 0.12 * span;
            lo = std::max(lo, std::min(0.02 * hi, 0.5 * smallest));
        };
        double kx = 1e300, ky = 1e300;
        for (const auto& v : vehicles) {
            kx = std::min(kx, v.parameters.at("k1"));
            ky = std::min(ky, v.parameters.at("k2"));
        }
        widen(x0, x1, kx);
        widen(y0, y1, ky);
        spec.x.lo = x0;
        spec.x.hi = x1;
        spec.y.lo = y0;
        spec.y.hi = y1;
        // the widened window may reach past the computable range (a vehicle near its edge): pull
        // the upper ends back towards the vehicles' largest (k1, k2) until every panel's corners
        // are inside (c grows with k1, k2); a vehicle outside the range is refused by classify
        double kx1 = -1e300, ky1 = -1e300;
        for (const auto& v : vehicles) {
            kx1 = std::max(kx1, v.parameters.at("k1"));
            ky1 = std::max(ky1, v.parameters.at("k2"));
        }
        auto inside = [&](double t) {
            ChartSpec trial = spec;
            trial.x.hi = kx1 + t * (x1 - kx1);
            trial.y.hi = ky1 + t * (y1 - ky1);
            try {
                for (std::size_t i = 0; i < trial.panels.size(); ++i) panel_sweep(trial, i).validate();
            } catch (const std::invalid_argument&) {
                return false;
            }
            return true;
        };
        if (!inside(1.0) && inside(0.0)) {
            double lo = 0.0, hi = 1.0;
            for (int it = 0; it < 40; ++it) (inside(0.5 * (lo + hi)) ? lo : hi) = 0.5 * (lo + hi);
            spec.x.hi = kx1 + lo * (x1 - kx1);
            spec.y.hi = ky1 + lo * (y1 - ky1);
        }
    } else if (cars != 22) {
        spec.title = "Calibrated vehicles on their own stability charts, " + ring;
    }
    return spec;
}

std::string bifurcation_svg(const EquilibriumBranch* eq, const OrbitBranch& orbits, int variable, const std::string& variable_name,
                            const std::string& variable_unit, const std::string& parameter_unit, const std::string& title,
                            const OrbitBranch* doubled) {
    const std::string orbit_colour = "#1f77b4", eq_colour = "#000000", doubled_colour = "#ff7f0e";
    std::vector<PlotSeries> series;
    // consecutive points of one stability form a piece; neighbouring pieces share their end point.
    // States: 1 stable (solid), 0 unstable (dashed), 2 undecided (no multipliers, or an orbit
    // that failed its accuracy check: grey, dashed, never drawn as either verdict)
    auto pieces = [&series](const std::vector<double>& x, const std::vector<double>& y, const std::vector<int>& state, const std::string& what,
                            const std::string& colour) {
        std::size_t start = 0;
        for (std::size_t i = 1; i <= x.size(); ++i) {
            if (i < x.size() && state[i] == state[start]) continue;
            const int k = state[start];
            PlotSeries s{(k == 1 ? "stable " : k == 0 ? "unstable " : "undecided ") + what, {}, {}, k == 2 ? std::string("#999999") : colour, k != 1};
            const std::size_t end = std::min(i + 1, x.size());
            s.x.assign(x.begin() + static_cast<std::ptrdiff_t>(start), x.begin() + static_cast<std::ptrdiff_t>(end));
            s.y.assign(y.begin() + static_cast<std::ptrdiff_t>(start), y.begin() + static_cast<std::ptrdiff_t>(end));
            series.push_back(std::move(s));
            start = i;
        }
    };
    std::vector<double> x, y;
    std::vector<int> st;
    for (const PeriodicOrbit& p : orbits.points) {
        x.push_back(p.par);
        y.push_back(p.max[variable] - p.min[variable]);
        st.push_back(!p.undecided.empty() || p.multipliers.empty() ? 2 : p.stable ? 1 : 0);
    }
    if (!x.empty()) pieces(x, y, st, "periodic orbits", orbit_colour);
    // the branch of twice the period: its own points, states and special points
    std::vector<double> dx, dy;
    std::vector<int> dst;
    if (doubled) {
        // drawn from the period doubling it starts at (the point of `orbits` nearest its first
        // orbit): the orbit there traversed twice belongs to both branches
        if (!doubled->points.empty() && !orbits.period_doublings.empty()) {
            const PeriodicOrbit& f = doubled->points.front();
            const OrbitCrossing* start = nullptr;
            for (const OrbitCrossing& c : orbits.period_doublings)
                if (c.located && c.orbit.max.size() > variable && (!start || std::abs(c.par - f.par) < std::abs(start->par - f.par))) start = &c;
            if (start) {
                dx.push_back(start->par);
                dy.push_back(start->orbit.max[variable] - start->orbit.min[variable]);
                dst.push_back(!f.undecided.empty() || f.multipliers.empty() ? 2 : f.stable ? 1 : 0);
            }
        }
        for (const PeriodicOrbit& p : doubled->points) {
            dx.push_back(p.par);
            dy.push_back(p.max[variable] - p.min[variable]);
            dst.push_back(!p.undecided.empty() || p.multipliers.empty() ? 2 : p.stable ? 1 : 0);
        }
        if (!dx.empty()) pieces(dx, dy, dst, "orbits of twice the period", doubled_colour);
    }
    std::vector<PlotMarker> markers;
    if (eq) {
        std::vector<double> ex, ey;
        std::vector<int> es;
        for (const EquilibriumPoint& p : eq->points) {
            ex.push_back(p.par);
            ey.push_back(0.0);
            es.push_back(p.stable ? 1 : 0);
        }
        if (!ex.empty()) pieces(ex, ey, es, "equilibria", eq_colour);
        for (const HopfPoint& h : eq->hopf) markers.push_back({h.par, 0.0, "#d62728", "Hopf"});
    }
    for (const OrbitFold& f : orbits.folds) markers.push_back({f.par, f.orbit.max[variable] - f.orbit.min[variable], "#2ca02c", "fold"});
    for (const OrbitCrossing& c : orbits.period_doublings) markers.push_back({c.par, 0.0, "#9467bd", "PD"});
    for (const OrbitCrossing& c : orbits.tori) markers.push_back({c.par, 0.0, "#8c564b", "torus"});
    // the markers of PD and tori are put on the branch by interpolation between its orbits
    auto place = [](std::vector<PlotMarker>& ms, std::size_t from, const std::vector<double>& bx, const std::vector<double>& by) {
        for (std::size_t k = from; k < ms.size(); ++k) {
            PlotMarker& m = ms[k];
            if (m.label != "PD" && m.label != "torus") continue;
            for (std::size_t i = 0; i + 1 < bx.size(); ++i)
                if ((bx[i] - m.x) * (bx[i + 1] - m.x) <= 0.0 && bx[i] != bx[i + 1]) {
                    m.y = by[i] + (m.x - bx[i]) / (bx[i + 1] - bx[i]) * (by[i + 1] - by[i]);
                    break;
                }
        }
    };
    place(markers, 0, x, y);
    if (doubled) {
        const std::size_t from = markers.size();
        for (const OrbitFold& f : doubled->folds) markers.push_back({f.par, f.orbit.max[variable] - f.orbit.min[variable], "#2ca02c", "fold"});
        for (const OrbitCrossing& c : doubled->period_doublings) markers.push_back({c.par, 0.0, "#9467bd", "PD"});
        for (const OrbitCrossing& c : doubled->tori) markers.push_back({c.par, 0.0, "#8c564b", "torus"});
        place(markers, from, dx, dy);
    }
    auto label = [](const std::string& name, const std::string& unit) { return unit.empty() ? name : name + " [" + unit_text(unit) + "]"; };
    PlotPanel panel{title, label(parameter_symbol(orbits.parameter), parameter_unit), "amplitude max - min of " + label(variable_name, variable_unit),
                    std::move(series), std::move(markers)};
    panel.y_floor = 0.0;  // an amplitude max - min is never negative
    PlotOptions po;
    po.columns = 1;
    po.panel_width = 640.0;
    po.panel_height = 360.0;
    po.note = "crosses: Hopf points (red), folds of periodic orbits (green); solid: stable, dashed: unstable";
    // bistability: between consecutive special points (where stability can change) a stable orbit
    // and a stable equilibrium both exist at the interval's midpoint
    if (eq && !eq->points.empty() && x.size() > 1) {
        std::vector<double> cuts;
        // the extent of the orbits (their folds included) and of the equilibria
        double olo = *std::min_element(x.begin(), x.end()), ohi = *std::max_element(x.begin(), x.end());
        for (const OrbitFold& f : orbits.folds) {
            olo = std::min(olo, f.par);
            ohi = std::max(ohi, f.par);
        }
        for (const EquilibriumPoint& p : eq->points) cuts.push_back(p.par);
        std::sort(cuts.begin(), cuts.end());
        cuts = {cuts.front(), cuts.back()};
        for (const HopfPoint& h : eq->hopf) cuts.push_back(h.par);
        for (const FoldPoint& f : eq->folds) cuts.push_back(f.par);
        for (const OrbitFold& f : orbits.folds) cuts.push_back(f.par);
        for (const OrbitCrossing& c : orbits.period_doublings) cuts.push_back(c.par);
        for (const OrbitCrossing& c : orbits.tori) cuts.push_back(c.par);
        if (doubled) {
            for (const OrbitFold& f : doubled->folds) cuts.push_back(f.par);
            for (const OrbitCrossing& c : doubled->period_doublings) cuts.push_back(c.par);
            for (const OrbitCrossing& c : doubled->tori) cuts.push_back(c.par);
            if (!dx.empty()) {
                cuts.push_back(*std::min_element(dx.begin(), dx.end()));
                cuts.push_back(*std::max_element(dx.begin(), dx.end()));
            }
        }
        std::sort(cuts.begin(), cuts.end());
        // stable at m: m lies between two neighbouring points that are both stable
        auto stable_at = [](const std::vector<double>& px, const std::vector<int>& ps, double m) {
            for (std::size_t i = 0; i + 1 < px.size(); ++i)
                if ((px[i] - m) * (px[i + 1] - m) <= 0.0 && ps[i] == 1 && ps[i + 1] == 1) return true;
            return false;
        };
        std::vector<double> ex;
        std::vector<int> es;
        for (const EquilibriumPoint& p : eq->points) {
            ex.push_back(p.par);
            es.push_back(p.stable ? 1 : 0);
        }
        // the bistable windows: neighbouring qualifying intervals merged, separate ones kept apart
        // (the 3-car optimal-velocity ring has two, on either side of the unstable equilibria)
        std::vector<std::pair<double, double>> windows;
        for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
            if (!(cuts[i + 1] > cuts[i])) continue;
            const double m = 0.5 * (cuts[i] + cuts[i + 1]);
            if (!(stable_at(x, st, m) || (doubled && stable_at(dx, dst, m))) || !stable_at(ex, es, m)) continue;
            if (!windows.empty() && windows.back().second == cuts[i]) windows.back().second = cuts[i + 1];
            else windows.emplace_back(cuts[i], cuts[i + 1]);
        }
        std::string text;
        for (auto [lo, hi] : windows) {
            lo = std::max(lo, olo);
            hi = std::min(hi, ohi);
            if (!(hi > lo)) continue;
            text += (text.empty() ? "" : " and ") + std::string("[") + rounded(lo, 4) + ", " + rounded(hi, 4) + "]";
        }
        if (!text.empty())
            po.note = "bistable (stable orbit and stable equilibrium) for " + parameter_symbol(orbits.parameter) + " in " + text +
                      "; crosses: Hopf red, fold green";
    }
    if (doubled) po.note += "; orange: orbits of twice the period";
    if (std::count(st.begin(), st.end(), 2) + std::count(dst.begin(), dst.end(), 2) > 0) po.note += "; grey: orbits without a stability verdict";
    return render_line_plots_svg({panel}, po);
}

namespace {
/// The Hopf curves in pieces of one criticality (neighbouring pieces share their end point), red:
/// solid where supercritical, dashed where subcritical, grey where L1 is not decided; the
/// generalised Hopf points marked GH, and with `codim2` also the double Hopf (DH) and zero-Hopf
/// (ZH) points.
void add_hopf_curves(PlotPanel& panel, const HopfCurves& curves, bool codim2) {
    for (const HopfCurve& c : curves.curves) {
        std::size_t start = 0;
        auto kind = [&](std::size_t i) {
            const HopfCoefficients& k = c.points[i].coefficients;
            return k.status != Status::Converged ? 0 : k.l1 < 0.0 ? 1 : k.l1 > 0.0 ? 2 : 0;
        };
        for (std::size_t i = 1; i <= c.points.size(); ++i) {
            if (i < c.points.size() && kind(i) == kind(start)) continue;
            const int k = kind(start);
            PlotSeries sr{k == 1 ? "Hopf, supercritical (L1 < 0)" : k == 2 ? "Hopf, subcritical (L1 > 0)" : "Hopf, L1 not decided", {}, {},
                          k == 0 ? std::string("#999999") : std::string("#d62728"), k != 1};
            for (std::size_t j = start; j < std::min(i + 1, c.points.size()); ++j) {
                sr.x.push_back(c.points[j].par);
                sr.y.push_back(c.points[j].par2);
            }
            panel.series.push_back(std::move(sr));
            start = i;
        }
        for (const GeneralisedHopfPoint& g : c.generalised)
            if (g.status == Status::Converged) panel.markers.push_back({g.par, g.par2, "#000000", "GH"});
        if (!codim2) continue;
        for (const DoubleHopfPoint& d : c.double_hopf)
            if (d.status == Status::Converged) panel.markers.push_back({d.par, d.par2, "#000000", "DH"});
        for (const ZeroHopfPoint& z : c.zero_hopf)
            if (z.status == Status::Converged) panel.markers.push_back({z.par, z.par2, "#000000", "ZH"});
        for (const HopfCurveBogdanovTakens& b : c.bogdanov_takens)
            if (b.status == Status::Converged) panel.markers.push_back({b.par, b.par2, "#000000", "BT"});
    }
}
}  // namespace

std::string bistability_svg(const BistabilityChart& chart, const std::string& unit, const std::string& unit2, const std::string& title) {
    PlotPanel panel;
    panel.title = "";
    auto label = [](const std::string& name, const std::string& u) { return u.empty() ? name : name + " [" + unit_text(u) + "]"; };
    panel.x_label = label(parameter_symbol(chart.parameter), unit);
    panel.y_label = label(parameter_symbol(chart.parameter2), unit2);
    panel.x_min = chart.from;
    panel.x_max = chart.to;
    panel.y_min = chart.from2;
    panel.y_max = chart.to2;
    // the cells: a polygon through the ends of their intervals (one per line), else one
    // rectangle per interval (a cell with several intervals on a line)
    PlotFill bistable{"bistable: stable wave and stable uniform flow", {}, "#f4a340", 0.55};
    PlotFill unstable{"equilibrium unstable", {}, "#9e9e9e", 0.35};
    PlotFill undecided{"undecided", {}, "#404040", 0.6};
    int rows = 0;
    for (const BistabilityCell& c : chart.cells) rows = std::max<int>(rows, static_cast<int>(c.intervals.size()));
    for (const BistabilityCell& c : chart.cells) {
        PlotFill* f = c.status != Status::Converged ? &undecided : c.bistable ? &bistable : !c.equilibrium_stable ? &unstable : nullptr;
        if (!f || c.intervals.empty()) continue;
        // the lines' spacing: the smallest gap between two of its lines
        double dy = chart.to2 - chart.from2;
        for (std::size_t i = 0; i + 1 < c.intervals.size(); ++i)
            if (c.intervals[i + 1].par2 > c.intervals[i].par2) dy = std::min(dy, c.intervals[i + 1].par2 - c.intervals[i].par2);
        bool one_per_line = true;
        for (std::size_t i = 0; i + 1 < c.intervals.size(); ++i) one_per_line = one_per_line && c.intervals[i + 1].par2 > c.intervals[i].par2;
        if (one_per_line && c.intervals.size() > 1) {
            std::vector<std::pair<double, double>> poly;
            const double y0 = std::max(chart.from2, c.intervals.front().par2 - 0.5 * dy), y1 = std::min(chart.to2, c.intervals.back().par2 + 0.5 * dy);
            poly.emplace_back(c.intervals.front().lo, y0);
            for (const auto& iv : c.intervals) poly.emplace_back(iv.lo, iv.par2);
            poly.emplace_back(c.intervals.back().lo, y1);
            poly.emplace_back(c.intervals.back().hi, y1);
            for (auto it = c.intervals.rbegin(); it != c.intervals.rend(); ++it) poly.emplace_back(it->hi, it->par2);
            poly.emplace_back(c.intervals.front().hi, y0);
            f->polygons.push_back(std::move(poly));
        } else {
            for (const auto& iv : c.intervals)
                f->polygons.push_back({{iv.lo, iv.par2 - 0.5 * dy}, {iv.hi, iv.par2 - 0.5 * dy}, {iv.hi, iv.par2 + 0.5 * dy}, {iv.lo, iv.par2 + 0.5 * dy}});
        }
    }
    for (PlotFill* f : {&bistable, &unstable, &undecided})
        if (!f->polygons.empty()) panel.fills.push_back(std::move(*f));
    add_hopf_curves(panel, chart.hopf, false);
    // a bistable cell narrower than 0.5 % of the box on its widest line (as beside a generalised
    // Hopf point with a small L2) would not show: marked at its representative point
    bool thin = false;
    for (const BistabilityCell& c : chart.cells) {
        if (!c.bistable || c.status != Status::Converged) continue;
        double widest = 0.0;
        for (const auto& iv : c.intervals) widest = std::max(widest, iv.hi - iv.lo);
        if (widest < 0.005 * (chart.to - chart.from)) {
            panel.markers.push_back({c.par, c.par2, "#c05800", "B"});
            thin = true;
        }
    }
    for (const OrbitFoldCurve& c : chart.folds) {
        PlotSeries sr{"fold of periodic orbits", {}, {}, "#2ca02c", false};
        for (const OrbitFoldCurvePoint& q : c.points) {
            sr.x.push_back(q.par);
            sr.y.push_back(q.par2);
        }
        panel.series.push_back(std::move(sr));
    }
    PlotOptions po;
    po.title = title;
    po.columns = 1;
    po.panel_width = 560.0;
    po.panel_height = 420.0;
    po.note = "shading: the verdict of each cell of the box cut by the curves, from a slice in " + parameter_symbol(chart.parameter) +
              " at one point of it (orbits born at a Hopf point; isolas not seen); GH: generalised Hopf point (L1 = 0)" +
              (thin ? std::string("; B: a bistable cell too thin to see (below 0.5 % of the box wide)") : std::string());
    return render_line_plots_svg({panel}, po);
}

std::string two_parameter_svg(const HopfCurves* hopf, const FoldCurves* folds, const std::string& parameter, const std::string& parameter2,
                              double from, double to, double from2, double to2, const std::string& unit, const std::string& unit2,
                              const std::string& title, const OrbitBranchCurves* orbit_curves) {
    PlotPanel panel;
    auto label = [](const std::string& name, const std::string& u) { return u.empty() ? name : name + " [" + unit_text(u) + "]"; };
    panel.x_label = label(parameter_symbol(parameter), unit);
    panel.y_label = label(parameter_symbol(parameter2), unit2);
    panel.x_min = from;
    panel.x_max = to;
    panel.y_min = from2;
    panel.y_max = to2;
    if (hopf) add_hopf_curves(panel, *hopf, true);
    if (folds)
        for (const FoldCurve& c : folds->curves) {
            PlotSeries sr{"fold of equilibria", {}, {}, "#1f77b4", false};
            for (const FoldCurvePoint& q : c.points) {
                sr.x.push_back(q.par);
                sr.y.push_back(q.par2);
            }
            panel.series.push_back(std::move(sr));
            for (const FoldCurveSpecialPoint& q : c.special)
                if (q.status == Status::Converged)
                    panel.markers.push_back({q.par, q.par2, "#000000", q.kind == "cusp" ? "CP" : q.kind == "bogdanov_takens" ? "BT" : "ZH"});
        }
    bool gh = false, dh = false, zh = false;
    if (orbit_curves) {
        struct Kind {
            const std::vector<OrbitFoldCurve>* curves;
            const char* name;
            const char* colour;
            const char* end;  // the marker where a curve ends on the orbits' shrinking (stop "hopf")
        };
        for (const Kind& k : {Kind{&orbit_curves->folds, "fold of periodic orbits", "#2ca02c", "GH"},
                              Kind{&orbit_curves->period_doublings, "period doubling", "#9467bd", ""},
                              Kind{&orbit_curves->tori, "torus bifurcation", "#8c564b", "DH"}})
            for (const OrbitFoldCurve& c : *k.curves) {
                PlotSeries sr{k.name, {}, {}, k.colour, false};
                for (const OrbitFoldCurvePoint& q : c.points) {
                    sr.x.push_back(q.par);
                    sr.y.push_back(q.par2);
                }
                panel.series.push_back(std::move(sr));
                if (c.points.empty() || !*k.end) continue;
                for (const auto& [end, stop] : {std::pair<const OrbitFoldCurvePoint*, std::string>{&c.points.front(), c.stop_backward},
                                                std::pair<const OrbitFoldCurvePoint*, std::string>{&c.points.back(), c.stop_forward}}) {
                    if (stop != "hopf") continue;
                    const std::string label = std::string(k.end) == "GH" ? "GH" : orbit_curve_end_point(*end);
                    panel.markers.push_back({end->par, end->par2, "#000000", label});
                    (label == "GH" ? gh : label == "DH" ? dh : zh) = true;
                }
            }
    }
    PlotOptions po;
    po.title = title;
    po.columns = 1;
    po.panel_width = 560.0;
    po.panel_height = 420.0;
    std::string note;
    if (hopf) note = "GH: generalised Hopf (L1 = 0), DH: double Hopf, ZH: zero-Hopf, BT: Bogdanov-Takens";
    if (folds) note += std::string(note.empty() ? "" : "; ") + "CP: cusp, BT: Bogdanov-Takens (a Hopf curve ends there)" + (hopf ? "" : ", ZH: zero-Hopf");
    if (!hopf && (gh || dh || zh)) {
        std::string ends;
        for (const auto& [shown, text] : {std::pair<bool, const char*>{gh, "GH generalised Hopf"}, {dh, "DH double Hopf"}, {zh, "ZH zero-Hopf"}})
            if (shown) ends += std::string(ends.empty() ? "" : ", ") + text;
        note += std::string(note.empty() ? "" : "; ") + "curves of orbits end where the orbits shrink onto an equilibrium: " + ends;
    }
    po.note = note;
    return render_line_plots_svg({panel}, po);
}

}  // namespace ddemap
