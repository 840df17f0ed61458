#include "ddemap/io/json.hpp"


#include <cmath>

#include <nlohmann/json.hpp>

#include "io/internal/json_values.hpp"

#include "ddemap/analysis/design/design.hpp"
#include "ddemap/io/svg.hpp"  // region_class

namespace ddemap {

namespace {

using json = nlohmann::ordered_json;

const auto num = detail::json_value;
json ring_value(int cars) { return cars == 0 ? json("inf") : json(cars); }
json params(const ParameterMap& p) {
    json o = json::object();
    for (const auto& [k, v] : p) o[k] = num(v);
    return o;
}
std::string text(const json& j) { return detail::json_text(j); }

}  // namespace

JsonObject& JsonObject::number(const std::string& key, double v) {
    m_items.emplace_back(key, detail::json_text(num(v)));
    return *this;
}
JsonObject& JsonObject::integer(const std::string& key, long long v) {
    m_items.emplace_back(key, detail::json_text(nlohmann::ordered_json(v)));
    return *this;
}
JsonObject& JsonObject::boolean(const std::string& key, bool v) {
    m_items.emplace_back(key, v ? "true" : "false");
    return *this;
}
JsonObject& JsonObject::string(const std::string& key, const std::string& v) {
    m_items.emplace_back(key, detail::json_text(nlohmann::ordered_json(v)));
    return *this;
}
JsonObject& JsonObject::null(const std::string& key) {
    m_items.emplace_back(key, "null");
    return *this;
}
JsonObject& JsonObject::json(const std::string& key, const std::string& json_text) {
    m_items.emplace_back(key, json_text);
    return *this;
}
std::string JsonObject::str() const {
    std::string s = "{";
    for (std::size_t i = 0; i < m_items.size(); ++i) {
        if (i) s += ",";
        s += ddemap::json_string(m_items[i].first) + ":" + m_items[i].second;
    }
    return s + "}";
}

std::string json_array(const std::vector<std::string>& items) {
    std::string s = "[";
    for (std::size_t i = 0; i < items.size(); ++i) s += (i ? "," : "") + items[i];
    return s + "]";
}
std::string json_number(double v) { return detail::json_text(num(v)); }
std::string json_string(const std::string& s) { return detail::json_text(nlohmann::json(s)); }
std::string json_ring(int cars) { return detail::json_text(ring_value(cars)); }
std::string json_parameters(const ParameterMap& p) { return detail::json_text(params(p)); }

std::string envelope_json(const JsonEnvelope& e) {
    json j;
    j["command"] = e.command;
    j["version"] = DDEMAP_VERSION;
    j["inputs"] = json::parse(e.inputs);
    j["solver"] = e.has_solver ? json{{"given", e.solver_given}, {"used", e.solver_used}} : json(nullptr);
    j["status"] = e.status;
    j["message"] = e.message;
    j["result"] = json::parse(e.result);
    return detail::json_text(j, 2) + "\n";
}

namespace {
json root_json(const Root& x) {
    return {{"re", num(x.value.real())}, {"im", num(x.value.imag())}, {"residual", num(x.residual)}, {"newton_step", num(x.newton_step)}};
}
}  // namespace

std::string ring_roots_json(const RingResult& r) {
    json j;
    j["ring"] = ring_value(r.cars);
    json roots = json::array();
    for (const auto& x : r.roots) {
        json o;
        o["re"] = num(x.root.value.real());
        o["im"] = num(x.root.value.imag());
        o["mode"] = x.mode < 0 ? json(nullptr) : json(x.mode);
        o["theta"] = num(x.theta);
        o["residual"] = num(x.root.residual);
        o["newton_step"] = num(x.root.newton_step);
        roots.push_back(o);
    }
    j["roots"] = roots;
    j["spectral_abscissa"] = num(r.spectral_abscissa);
    j["abscissa_mode"] = r.abscissa_mode < 0 ? json(nullptr) : json(r.abscissa_mode);
    j["abscissa_theta"] = num(r.abscissa_theta);
    j["abscissa_is_limit"] = r.abscissa_is_limit;
    j["ring_stable"] = r.stable;
    j["ring_verdict"] = to_string(r.verdict);
    j["ring_margin"] = r.verdict == Verdict::Undecided ? json(nullptr) : num(-r.spectral_abscissa);
    j["unstable_roots"] = r.unstable_roots < 0 ? json(nullptr) : json(r.unstable_roots);
    j["marginal_roots"] = r.marginal_roots;
    j["trivial_root"] = {{"re", 0.0}, {"im", 0.0}, {"mode", 0}, {"excluded", true},
                         {"meaning", "ring-length invariance (family of equilibria)"}};
    j["degree"] = r.degree;
    j["degree_reason"] = r.reason;
    j["modes_solved"] = r.modes_solved;
    return text(j);
}

std::string system_roots_json(const LinearDDE& dde, const SystemRootResult& s) {
    const RootResult& r = s.roots;
    json j;
    j["dimension"] = dde.dimension();
    json delays = json::array();
    for (double t : dde.delays()) delays.push_back(t);
    j["delays"] = delays;
    json roots = json::array();
    for (const auto& x : r.roots) roots.push_back(root_json(x));
    j["roots"] = roots;
    j["spectral_abscissa"] = num(s.spectral_abscissa);
    j["stable"] = s.stable;
    j["verdict"] = to_string(s.verdict);
    j["degree"] = r.degree;
    j["degree_reason"] = r.message;
    j["strip_floor"] = num(r.strip_floor);
    return text(j);
}

std::string equilibrium_branch_json(const EquilibriumBranch& b, const std::vector<std::string>& variables) {
    const auto vec = detail::json_values;
    json j;
    j["parameter"] = b.parameter;
    j["variables"] = variables;
    json points = json::array();
    for (const EquilibriumPoint& p : b.points) {
        json o;
        o["par"] = num(p.par);
        o["x"] = vec(p.x);
        // no verdict where the roots did not converge: null
        const bool decided = p.roots_status == Status::Converged && std::isfinite(p.abscissa);
        o["abscissa"] = decided ? num(p.abscissa) : json(nullptr);
        o["unstable"] = decided ? json(p.unstable) : json(nullptr);
        o["stable"] = decided ? json(p.stable) : json(nullptr);
        o["roots_status"] = to_string(p.roots_status);
        json roots = json::array();
        for (const cplx& r : p.roots) roots.push_back(json::array({num(r.real()), num(r.imag())}));
        o["roots"] = roots;
        points.push_back(o);
    }
    j["points"] = points;
    json folds = json::array();
    for (const FoldPoint& f : b.folds) {
        json o;
        o["kind"] = f.kind;
        o["par"] = num(f.par);
        o["x"] = vec(f.x);
        o["status"] = to_string(f.status);
        o["residual"] = num(f.residual);
        folds.push_back(o);
    }
    j["folds"] = folds;
    json hopf = json::array();
    for (const HopfPoint& h : b.hopf) {
        json o;
        o["par"] = num(h.par);
        o["omega"] = num(h.omega);
        o["x"] = vec(h.x);
        o["status"] = to_string(h.status);
        o["residual"] = num(h.residual);
        hopf.push_back(o);
    }
    j["hopf"] = hopf;
    j["stop"] = to_string(b.stop);
    return text(j);
}

std::string fold_curves_json(const FoldCurves& c, const std::string& parameter2, const std::vector<std::string>& variables) {
    const auto vec = detail::json_values;
    json j;
    j["parameter"] = c.start.parameter;
    j["parameter2"] = parameter2;
    j["branch"] = json::parse(equilibrium_branch_json(c.start, variables));
    json curves = json::array();
    for (const FoldCurve& k : c.curves) {
        json o = detail::curve_json(k.start, k.status, k.message, k.stop_backward, k.stop_forward);
        json pts = json::array();
        for (const FoldCurvePoint& p : k.points) {
            json q;
            q["par"] = num(p.par);
            q["par2"] = num(p.par2);
            q["x"] = vec(p.x);
            q["cusp_test"] = num(p.cusp_test);
            q["bt_test"] = num(p.bt_test);
            q["residual"] = num(p.residual);
            q["unstable"] = p.unstable >= 0 ? json(p.unstable) : json(nullptr);
            pts.push_back(q);
        }
        o["points"] = pts;
        json sp = json::array();
        for (const FoldCurveSpecialPoint& p : k.special) {
            json q;
            q["kind"] = p.kind;
            q["par"] = num(p.par);
            q["par2"] = num(p.par2);
            q["x"] = vec(p.x);
            q["omega"] = p.kind == "zero_hopf" ? num(p.omega) : json(nullptr);
            // normal-form coefficients (normal_forms.hpp): a, b at a Bogdanov-Takens point, b, c at a cusp
            if (p.kind == "bogdanov_takens") q["normal_form"] = {{"a", num(p.nf_a)}, {"b", num(p.nf_b)}};
            else if (p.kind == "cusp") q["normal_form"] = {{"b", num(p.nf_b)}, {"c", num(p.nf_c)}};
            else q["normal_form"] = detail::zero_hopf_normal_form_json(p.zero_hopf);  // null when not formed
            q["test"] = num(p.test);
            q["other"] = num(p.other);
            q["status"] = to_string(p.status);
            q["residual"] = num(p.residual);
            q["after"] = p.after;
            sp.push_back(q);
        }
        o["special"] = sp;
        curves.push_back(o);
    }
    j["curves"] = curves;
    return text(j);
}

std::string mixed_ring_json(const MixedRingResult& r, std::size_t cars) {
    const RootResult& rr = r.roots;
    json j;
    j["ring"] = cars;
    j["speed"] = num(r.equilibrium.speed);
    j["length"] = num(r.equilibrium.length);
    json roots = json::array();
    for (std::size_t i = 0; i < rr.roots.size(); ++i) {
        json o = root_json(rr.roots[i]);
        const cplx eig = rr.roots[i].eigenvalue;
        o["eigenvalue_re"] = num(eig.real());
        o["eigenvalue_im"] = num(eig.imag());
        roots.push_back(o);
    }
    j["roots"] = roots;
    j["trivial_root_found"] = r.trivial_found;
    j["trivial_root_abs"] = num(r.trivial_root);
    j["spectral_abscissa"] = num(r.spectral_abscissa);
    j["ring_stable"] = r.stable;
    j["ring_verdict"] = to_string(r.verdict);
    j["ring_margin"] = r.verdict == Verdict::Undecided ? json(nullptr) : num(-r.spectral_abscissa);
    j["unstable_roots"] = r.unstable_roots;
    j["unstable_count_complete"] = r.unstable_count_complete;
    j["product_residual"] = num(r.product_residual);
    j["degree"] = rr.degree;
    j["degree_reason"] = rr.message;
    j["strip_floor"] = num(rr.strip_floor);
    j["right_bound"] = num(rr.right_bound);
    j["shifts"] = rr.shifts;
    j["factorizations"] = rr.factorizations;
    j["max_residual"] = num(rr.max_residual);
    j["collocation_error"] = num(rr.collocation_error);
    return text(j);
}

namespace {
/// Peak (L-infinity) string stability; peak_norm null when infinite (plant unstable) or undecided.
void add_peak(json& j, const PeakResult& p) {
    const bool decided = p.verdict != Verdict::Undecided;
    j["peak_verdict"] = to_string(p.verdict);
    j["peak_stable"] = decided ? json(p.verdict == Verdict::Stable) : json(nullptr);
    j["peak_norm"] = decided && p.finite ? num(p.norm) : json(nullptr);
    j["peak_norm_error"] = decided && p.finite ? num(p.error) : json(nullptr);
    j["peak_overshoot"] = decided && p.finite ? num(p.overshoot) : json(nullptr);
    j["peak_status"] = to_string(p.status);
    j["peak_message"] = p.message;
}
}  // namespace

std::string string_json(const StringResult& s, const RingResult* ring) {
    json j;
    j["plant_stable"] = s.plant_stable;
    j["plant_verdict"] = to_string(s.plant_verdict);
    j["plant_abscissa"] = num(s.plant_abscissa);
    j["plant_margin"] = num(-s.plant_abscissa);
    j["sup_gamma"] = num(s.sup_gamma);
    j["omega_peak"] = num(s.omega_peak);
    j["peak_margin"] = num(s.peak_margin);
    j["lowfreq_margin"] = num(s.lowfreq_margin);
    j["lowfreq"] = {{"c2", num(s.lowfreq.c2)}, {"c4", num(s.lowfreq.c4)}, {"c6", num(s.lowfreq.c6)},
                    {"c8", num(s.lowfreq.c8)}, {"decisive_order", s.lowfreq.decisive_order},
                    {"attenuates", s.lowfreq.attenuates}};
    j["string_stable"] = s.string_stable;
    j["string_verdict"] = to_string(s.string_verdict);
    json peaks = json::array();
    for (const auto& p : s.peaks) peaks.push_back({{"omega", num(p.omega)}, {"gain", num(p.gain)}});
    j["peaks"] = peaks;
    j["omega_search_max"] = num(s.omega_search_max);
    j["plant_degree"] = s.plant_roots.degree;
    if (s.peak) add_peak(j, *s.peak);
    if (ring) {
        j["ring"] = ring_value(ring->cars);
        j["ring_stable"] = ring->stable;
        j["ring_verdict"] = to_string(ring->verdict);
        j["spectral_abscissa"] = num(ring->spectral_abscissa);
        j["ring_margin"] = ring->verdict == Verdict::Undecided ? json(nullptr) : num(-ring->spectral_abscissa);
    }
    return text(j);
}

std::string classification_message(const std::vector<Classification>& rows) {
    for (const auto& r : rows) {
        if (r.string.plant_roots.status != Status::Converged) return r.vehicle.name + ": plant roots: " + r.string.plant_roots.message;
        if (r.ring.status != Status::Converged) return r.vehicle.name + ": ring: " + r.ring.reason;
        if (r.has_uncertainty && r.uncertainty.status != Status::Converged) return r.vehicle.name + ": " + r.uncertainty.message;
        if (r.has_distance && r.distance.status != Status::Converged) return r.vehicle.name + ": verdict distance: " + r.distance.message;
    }
    if (rows.empty()) return "";
    return std::to_string(rows.size()) + (rows.size() == 1 ? " car" : " cars") +
           ": every plant and ring root search converged with its certificate (" + rows.front().vehicle.name + "'s ring: " + rows.front().ring.reason +
           "); the string verdicts from the low-frequency coefficient c2 and the peak of |Gamma(i omega)|";
}

std::string sweep_message(const SweepResult& sw) {
    if (sw.uncertified > 0)
        return std::to_string(sw.uncertified) + (sw.uncertified == 1 ? " point has" : " points have") +
               " no certificate even after collocation (see their 'certified' column)";
    return "every one of the " + std::to_string(sw.points.size()) + " grid points certified: no root of the plant or of the ring (method " +
           sw.ring_method + ") lies right of the abscissa reported (argument principle)";
}

std::string growth_message(const std::vector<GrowthResult>& g) {
    for (const GrowthResult& r : g)
        if (r.status != Status::Converged) return r.name + ": " + r.message;
    return std::to_string(g.size()) + (g.size() == 1 ? " platoon" : " platoons") +
           " simulated to the end without divergence (classical Runge-Kutta of order 4, steps of at most the smallest delay, "
           "landing on the lead's breakpoints)";
}

std::string mix_message(const std::vector<MixPoint>& points) {
    int arrangements = 0;
    for (const MixPoint& p : points) {
        if (p.status != Status::Converged) return "p = " + json_number(p.fraction) + ": an arrangement's roots did not converge (" + to_string(p.status) + ")";
        arrangements += p.arrangements;
    }
    return "the roots of every one of the " + std::to_string(arrangements) + " arrangements located and certified as roots --fleet certifies them";
}

std::string calibration_message(const std::vector<std::string>& names, const std::vector<CalibrationResult>& fits) {
    for (std::size_t i = 0; i < fits.size(); ++i)
        if (fits[i].status_code != Status::Converged) return (i < names.size() ? names[i] : "fit " + std::to_string(i + 1)) + ": " + fits[i].message;
    if (fits.empty()) return "";
    return std::to_string(fits.size()) + (fits.size() == 1 ? " fit" : " fits") +
           " converged (bounded Levenberg-Marquardt with exact sensitivities from the best points of a Latin-hypercube design; " + fits.front().message +
           "); 95 % intervals from the covariance corrected for correlated residuals (Newey-West)";
}

std::string classification_json(const std::vector<Classification>& rows, int cars, const std::string& source) {
    json j;
    j["source"] = source;
    j["ring"] = ring_value(cars);
    json arr = json::array();
    for (const auto& row : rows) {
        json o;
        o["name"] = row.vehicle.name;
        for (const char* k : {"k1", "k2", "th", "tau", "eta"}) o[k] = num(row.vehicle.parameters.at(k));
        o["plant_stable"] = row.string.plant_stable;
        o["ring_stable"] = row.ring.stable;
        o["string_stable"] = row.string.string_stable;
        o["plant_verdict"] = to_string(row.string.plant_verdict);
        o["ring_verdict"] = to_string(row.ring.verdict);
        o["string_verdict"] = to_string(row.string.string_verdict);
        o["sup_gamma"] = num(row.string.sup_gamma);
        if (row.string.peak) add_peak(o, *row.string.peak);
        o["omega_peak"] = num(row.string.omega_peak);
        o["lowfreq_margin"] = num(row.string.lowfreq_margin);
        o["spectral_abscissa"] = num(row.ring.spectral_abscissa);
        o["plant_abscissa"] = num(row.string.plant_abscissa);
        o["attenuation_margin"] = num(row.attenuation_margin);  // null when the plant is not stable
        if (row.has_distance) {
            // the distance to the other L2 string verdict (classify --distance)
            const VerdictDistance& d = row.distance;
            json at = json::object();
            for (const auto& name : d.over)
                if (d.at.count(name)) at[name] = num(d.at.at(name));
            o["verdict_distance"] = {{"distance", num(d.distance)},
                                     {"to", d.from_stable ? "string unstable" : "string stable"},
                                     {"over", d.over},
                                     {"at", d.status == Status::Converged ? at : json(nullptr)},
                                     {"boundary", d.boundary.empty() ? json(nullptr) : json(d.boundary)},
                                     {"omega", num(d.omega)},
                                     {"status", to_string(d.status)},
                                     {"method", d.method},
                                     {"message", d.message}};
        }
        if (row.has_uncertainty) {
            // the verdicts under the calibration's parameter uncertainty (classify_with_uncertainty)
            const VerdictUncertainty& u = row.uncertainty;
            auto prob = [](const ProbabilityEstimate& e) {
                return json{{"p", num(e.p)}, {"standard_error", num(e.standard_error)}, {"wilson", {num(e.lower), num(e.upper)}},
                            {"count", e.successes}, {"samples", e.trials}};
            };
            auto range = [](const MarginInterval& m) { return json{num(m.lower), num(m.upper)}; };
            o["p_string_unstable"] = num(u.string_unstable.p);
            const bool ring = u.ring_unstable.trials > 0;
            o["margin_intervals"] = {{"c2", range(u.c2)}, {"sup_gamma_minus_1", range(u.sup_gamma_excess)},
                                     {"spectral_abscissa", ring ? range(u.ring_abscissa) : json(nullptr)}};
            o["uncertainty"] = {{"samples", u.samples},
                                {"draws", u.draws},
                                {"ring_samples", u.ring_samples},
                                {"undecided", u.undecided},
                                {"string_unstable", prob(u.string_unstable)},
                                {"ring_unstable", ring ? prob(u.ring_unstable) : json(nullptr)},
                                {"plant_unstable", prob(u.plant_unstable)},
                                {"medians", {{"c2", num(u.c2.median)}, {"sup_gamma_minus_1", num(u.sup_gamma_excess.median)},
                                             {"spectral_abscissa", ring ? num(u.ring_abscissa.median) : json(nullptr)}}},
                                {"status", to_string(u.status)},
                                {"message", u.message}};
            // the box the samples were restricted to and where it came from
            json box = json::object();
            for (const auto& b : u.domain) box[b.name] = {num(b.lower), num(b.upper)};
            o["uncertainty"]["bounds"] = box;
            o["uncertainty"]["bounds_source"] = u.domain_from_fit ? "file" : "default";
        }
        arr.push_back(o);
    }
    j["vehicles"] = arr;
    return text(j);
}

std::string sweep_json(const SweepResult& sw, const BoundarySet* b) {
    json j;
    j["model"] = sw.spec.model;
    json fixed = json::object();
    for (const auto& [k, v] : sw.spec.fixed) fixed[k] = num(v);
    j["fixed"] = fixed;
    for (const auto* a : {&sw.spec.x, &sw.spec.y}) {
        j[a == &sw.spec.x ? "x" : "y"] = {{"name", a->name}, {"lo", a->lo}, {"hi", a->hi}, {"count", a->count}};
    }
    j["ring"] = ring_value(sw.spec.cars);
    j["points"] = sw.points.size();
    int classes[5] = {0, 0, 0, 0, 0};
    for (const auto& p : sw.points) ++classes[region_class(p)];
    // string_stable counts every L2 string-stable point; with the peak notion, peak_stable those of
    // them whose step response does not overshoot
    j["regions"] = {{"plant_unstable", classes[0]}, {"ring_unstable", classes[1]}, {"string_unstable", classes[2]},
                    {"string_stable", classes[3] + classes[4]}};
    if (sw.spec.peak) j["regions"]["peak_stable"] = classes[4];
    j["peak"] = sw.spec.peak;
    j["method"] =
        "rightmost root of every ring mode and of the plant continued by Newton along grid rows, each certified by an "
        "argument-principle count (no zero right of Re + 1e-10 max(1,|lambda|)); Chebyshev collocation where a "
        "certificate fails";
    j["degree"] = sw.degree_max;
    j["fallbacks"] = sw.fallbacks;
    j["uncertified_points"] = sw.uncertified;
    j["threads"] = sw.threads;
    j["seconds"] = sw.seconds;
    j["points_per_second"] = sw.seconds > 0 ? sw.points.size() / sw.seconds : 0.0;
    if (b) {
        j["boundaries"] = {{"curves", b->curves.size()}, {"seeds", b->seeds}, {"rejected_seeds", b->rejected},
                           {"seconds", b->seconds}, {"ring_curves", ring_curves_name(b->ring_curves)},
                           {"off_envelope_seeds", b->off_envelope}, {"corners", b->corners}};
    }
    return text(j);
}

std::string boundary_json(const BoundarySet& b) {
    json curves = json::array();
    for (std::size_t i = 0; i < b.curves.size(); ++i) {
        const auto& c = b.curves[i];
        curves.push_back({{"branch", i + 1}, {"kind", kind_name(c.kind)}, {"subkind", subkind_name(c.kind)},
                          {"mode", c.kind == BoundaryKind::RingHopf ? json(c.mode) : json(nullptr)},
                          {"points", c.points.size()}, {"max_residual", num(c.max_residual)}, {"closed", c.closed}});
    }
    return text(json{{"curves", curves}, {"seeds", b.seeds}, {"rejected_seeds", b.rejected}, {"seconds", b.seconds},
                     {"ring_curves", ring_curves_name(b.ring_curves)}, {"off_envelope_seeds", b.off_envelope}, {"corners", b.corners}});
}

std::string simulation_json(const SimResult& r, const std::string& lead) {
    json j;
    j["lead"] = lead;
    j["initial_speed"] = num(r.initial_speed);
    j["t_end"] = num(r.t_end);
    j["stopped_at_event"] = r.stopped;
    j["diverged_at"] = r.status == Status::Converged ? json(nullptr) : num(r.diverged_at);
    j["steps"] = r.steps;
    json cs = json::array();
    for (const auto& c : r.cars) {
        json e = json::array();
        for (const auto& ev : c.events)
            e.push_back({{"type", ev.type}, {"time", num(ev.time)}, {"speed", num(ev.speed)}, {"gap", num(ev.gap)}});
        cs.push_back({{"car", c.car}, {"name", c.name}, {"lowest_speed", num(c.min_speed)}, {"speed_drop", num(c.speed_drop)},
                      {"min_gap", num(c.min_gap)}, {"events", e}});
    }
    j["cars"] = cs;
    return text(j);
}

std::string growth_json(const std::vector<GrowthResult>& g, const std::string& lead) {
    json arr = json::array();
    for (const auto& r : g) {
        arr.push_back({{"name", r.name}, {"speed_drop", r.speed_drop}, {"amplification", r.amplification}, {"min_gap", r.min_gap},
                       {"failed_at", r.failed_at}, {"failure", r.failure}, {"failure_time", num(r.failure_time)},
                       {"status", to_string(r.status)}, {"message", r.message}});
    }
    return text(json{{"lead", lead}, {"vehicles", arr}});
}

std::string calibration_json(const std::vector<std::string>& names, const std::vector<CalibrationResult>& fits,
                             const CalibrationOptions& o, const std::vector<CarCalibration>* cars) {
    json arr = json::array();
    for (std::size_t i = 0; i < fits.size(); ++i) {
        const CalibrationResult& r = fits[i];
        json j;
        j["name"] = i < names.size() ? names[i] : std::string();
        for (const char* k : {"k1", "k2", "th", "tau", "eta"}) j[k] = num(r.parameters.at(k));
        j["rmse_speed"] = num(r.all.rmse_speed);
        j["rmse_gap"] = num(r.all.rmse_gap);
        j["train"] = {{"rmse_speed", num(r.train.rmse_speed)}, {"rmse_gap", num(r.train.rmse_gap)}, {"samples", r.train.samples}};
        if (r.test.samples > 0)
            j["test"] = {{"rmse_speed", num(r.test.rmse_speed)}, {"rmse_gap", num(r.test.rmse_gap)}, {"samples", r.test.samples}};
        j["naive_rmse_speed"] = num(r.naive.rmse_speed);
        j["naive_delay"] = num(r.naive_delay);
        // uncertainty: 95 % intervals (null where the trace does not determine the parameter),
        // standard errors, the covariance and correlation in the order k1, k2, th, tau, eta
        json ci = json::object(), se = json::object();
        for (const auto& est : r.estimates) {
            ci[est.name] = {num(est.lower95), num(est.upper95)};
            se[est.name] = num(est.standard_error);
        }
        j["ci95"] = ci;
        j["standard_errors"] = se;
        json cov = json::array(), cor = json::array();
        for (int a = 0; a < 5; ++a) {
            json rc = json::array(), rr = json::array();
            for (int b = 0; b < 5; ++b) {
                rc.push_back(num(r.covariance(a, b)));
                rr.push_back(num(r.correlation(a, b)));
            }
            cov.push_back(rc);
            cor.push_back(rr);
        }
        j["covariance"] = cov;
        j["correlation"] = cor;
        j["effective_samples"] = num(r.effective_samples);
        // the lead speed's white noise the covariance allows for, per fitted run [m/s], and the
        // standard errors as they would be with the lead speed exact
        json ln = json::array();
        for (double x : r.lead_noise) ln.push_back(num(x));
        j["lead_noise"] = ln;
        j["lead_noise_corrected"] = r.lead_noise_corrected;
        json sex = json::object();
        for (int a = 0; a < 5; ++a) sex[r.estimates[static_cast<std::size_t>(a)].name] = num(std::sqrt(std::max(r.covariance_exact_lead(a, a), 0.0)));
        j["standard_errors_exact_lead"] = sex;
        j["warnings"] = r.warnings;
        j["objective"] = num(r.objective);
        j["minimised_objective"] = num(r.minimised_objective);
        j["starts"] = r.starts;
        j["status"] = r.status;
        j["message"] = r.message;
        j["evaluations"] = r.evaluations;
        j["seconds"] = r.seconds;
        if (cars && i < cars->size()) {
            // the fitted runs (whole files) and the test runs, each simulated from its own start
            const CarCalibration& c = (*cars)[i];
            auto run = [](const std::string& file, const FitEvaluation& ev) {
                return json{{"file", file},
                            {"rmse_speed", num(ev.errors.rmse_speed)},
                            {"rmse_gap", num(ev.errors.rmse_gap)},
                            {"naive_rmse_speed", num(ev.naive.rmse_speed)},
                            {"samples", ev.errors.samples}};
            };
            json tr = json::array(), te = json::array();
            for (std::size_t k = 0; k < c.train_sources.size() && k < r.runs.size(); ++k) tr.push_back(run(c.train_sources[k], r.runs[k]));
            for (const TestRun& t : c.tests) {
                json x = run(t.source, t.evaluation);
                x["type"] = t.type;
                te.push_back(x);
            }
            j["train_runs"] = tr;
            j["tests"] = te;
        }
        arr.push_back(j);
    }
    json j;
    j["fits"] = arr;
    j["gap_weight"] = o.gap_weight;
    j["bounds"] = json::object();
    for (const auto& name : calibration_parameter_names()) j["bounds"][name] = {o.bound(name).lower, o.bound(name).upper};
    return text(j);
}

std::string mix_json(const std::vector<MixPoint>& points, int cars) {
    json arr = json::array();
    for (const auto& pt : points) {
        arr.push_back({{"p", num(pt.fraction)}, {"x_cars", pt.x_cars}, {"spectral_abscissa", num(pt.abscissa)},
                       {"spectral_abscissa_min", num(pt.abscissa_min)}, {"spectral_abscissa_max", num(pt.abscissa_max)},
                       {"speed", num(pt.speed)}, {"ring_stable", pt.stable}, {"unstable_roots", pt.unstable_roots},
                       {"arrangements", pt.arrangements}, {"max_residual", num(pt.max_residual)}, {"status", to_string(pt.status)}});
    }
    return text(json{{"ring", cars}, {"points", arr}});
}

std::string orbit_fold_curves_json(const std::vector<OrbitFoldCurve>& curves, const std::vector<std::string>& variables) {
    const auto vec = detail::json_values;
    json all = json::array();
    for (const OrbitFoldCurve& c : curves) {
        json j;
        j["parameter"] = c.parameter;
        j["parameter2"] = c.parameter2;
        j["variables"] = variables;
        j["degree"] = c.degree;
        j["intervals"] = c.intervals;
        j["start"] = c.start;
        json points = json::array();
        for (const OrbitFoldCurvePoint& q : c.points)
            points.push_back({{"par", num(q.par)}, {"par2", num(q.par2)}, {"period", num(q.orbit.period)}, {"min", vec(q.orbit.min)},
                              {"max", vec(q.orbit.max)}, {"fold_test", num(q.test)}, {"second_distance", num(q.second_distance)},
                              {"trivial_distance", num(q.orbit.trivial_distance)}, {"residual", num(q.orbit.residual)}});
        for (std::size_t i = 0; i < c.points.size(); ++i)
            if (std::isfinite(c.points[i].rotation)) points[i]["rotation"] = num(c.points[i].rotation);
        j["points"] = points;
        j["stop_backward"] = c.stop_backward;
        j["stop_forward"] = c.stop_forward;
        j["status"] = to_string(c.status);
        j["message"] = c.message;
        j["method"] = c.method;
        j["certificate"] = {{"max_residual", num(c.max_residual)}, {"max_fold_test", num(c.max_test)},
                            {"max_trivial_distance", num(c.max_trivial_distance)}};
        all.push_back(j);
    }
    return text(all);
}

std::string simulation_start_json(const SimulatedOrbitGuess& g, double t_end, double step) {
    JsonObject start;
    start.string("kind", "simulation").number("t_end", t_end).number("step", step).number("period", g.period)
        .integer("crossings_per_period", g.crossings_per_period).number("period_spread", g.period_spread).string("status", to_string(g.status))
        .string("message", g.message);
    return start.str();
}

std::string orbit_branch_json(const OrbitBranch& b, const std::vector<std::string>& variables, int multipliers) {
    const auto vec = detail::json_values;
    auto pair = [](cplx z) { return json::array({num(z.real()), num(z.imag())}); };
    json j;
    j["parameter"] = b.parameter;
    j["variables"] = variables;
    j["degree"] = b.degree;
    j["intervals"] = b.intervals;
    json points = json::array();
    for (const PeriodicOrbit& p : b.points) {
        json o;
        o["par"] = num(p.par);
        o["period"] = num(p.period);
        o["min"] = vec(p.min);
        o["max"] = vec(p.max);
        o["stable"] = p.undecided.empty() && !p.multipliers.empty() ? json(p.stable) : json(nullptr);  // null: no verdict
        if (!p.undecided.empty()) o["undecided"] = p.undecided;
        json m = json::array();
        for (std::size_t k = 0; k < p.multipliers.size() && static_cast<int>(k) < multipliers; ++k) m.push_back(pair(p.multipliers[k]));
        o["multipliers"] = m;
        o["trivial_distance"] = num(p.trivial_distance);
        o["residual"] = num(p.residual);
        points.push_back(o);
    }
    j["points"] = points;
    json folds = json::array();
    for (const OrbitFold& f : b.folds) folds.push_back({{"par", num(f.par)}, {"period", num(f.period)}, {"located", f.located}});
    j["folds"] = folds;
    for (const char* key : {"period_doublings", "tori"}) {
        json a = json::array();
        for (const OrbitCrossing& x : std::string(key) == "tori" ? b.tori : b.period_doublings)
            a.push_back({{"par", num(x.par)}, {"period", num(x.period)}, {"multiplier", pair(x.multiplier)}, {"located", x.located},
                         {"accuracy", num(x.accuracy)}, {"par_bracket", num(x.par_bracket)}});
        j[key] = a;
    }
    j["stop"] = b.stop;
    j["method"] = b.method;
    j["certificate"] = {{"max_residual", num(b.max_residual)}, {"max_trivial_distance", num(b.max_trivial_distance)}};
    return text(j);
}

std::string append_ring_method_json(const std::string& object_text, const FastRing& f) {
    JsonObject o;
    o.string("ring_method", f.method_used).string("listed_by", f.listed_by);
    if (f.winding_ran) {
        const RingWindingResult& w = f.winding;
        JsonObject wj;
        wj.string("status", to_string(w.status))
            .boolean("certified", w.certified)
            .string("verdict", to_string(w.verdict))
            .integer("unstable_roots", w.unstable_roots)
            .integer("marginal_roots", w.marginal_roots)
            .number("spectral_abscissa", w.spectral_abscissa)
            .integer("tables", w.tables)
            .integer("evaluations", w.evaluations)
            .boolean("fell_back_to_modes", f.fell_back)
            .string("message", w.message);
        o.json("winding", wj.str());
    } else {
        o.null("winding");
    }
    std::string text = object_text;
    const std::string extra = o.str();
    while (!text.empty() && text.back() != '}') text.pop_back();
    if (text.empty()) return extra;
    text.pop_back();
    return text + (text.size() > 1 ? "," : "") + extra.substr(1);
}

JsonObject& add_held_parameters(JsonObject& o, const NonlinearDDE& system, const std::string& free_parameter) {
    (void)system.parameter_index(free_parameter);  // an unknown name: std::invalid_argument naming the known ones
    for (std::size_t i = 0; i < system.parameter_names().size(); ++i) {
        const std::string& name = system.parameter_names()[i];
        if (name != free_parameter) o.number(name, system.parameter_values()[i]);
    }
    return o;
}

std::string equilibrium_result_json(const EquilibriumResult& eq) {
    std::vector<std::string> xs;
    for (Eigen::Index i = 0; i < eq.x.size(); ++i) xs.push_back(json_number(eq.x[i]));
    return JsonObject()
        .json("x", json_array(xs))
        .number("residual", eq.residual)
        .integer("iterations", eq.iterations)
        .string("status", to_string(eq.status))
        .string("message", eq.message)
        .str();
}

std::string travelling_wave_json(const TravellingWaveBranch& w, const std::vector<std::string>& variables, int multipliers) {
    json j = json::parse(orbit_branch_json(w.branch, variables, multipliers));
    for (std::size_t i = 0; i < w.branch.points.size(); ++i)
        if (w.branch.points[i].multipliers.empty()) j["points"][i]["stable"] = nullptr;
    json wave;
    wave["cars"] = w.cars;
    wave["wave"] = w.wave;
    wave["shift"] = num(static_cast<double>(w.wave) / w.cars);
    wave["hopf"] = {{"par", num(w.hopf.par)}, {"omega", num(w.hopf.omega)}, {"status", to_string(w.hopf.status)}};
    wave["stability"] = w.full_ring_stability ? "full_ring" : "not_computed";
    // the method of the multipliers: "dense" (N <= 10), "matrix_free" (Arnoldi; per wave its
    // status and message, stable null when undecided) or "none"
    wave["stability_method"] = w.stability_method;
    if (w.stability_method == "matrix_free") {
        for (std::size_t i = 0; i < w.branch.points.size() && i < w.stability.size(); ++i) {
            const WaveStability& s = w.stability[i];
            j["points"][i]["stability_status"] = to_string(s.status);
            j["points"][i]["stability_message"] = s.message;
            if (s.status != Status::Converged) j["points"][i]["stable"] = nullptr;
        }
        wave["stability_status"] = to_string(w.stability_status);
    }
    wave["max_drift"] = num(w.max_drift);
    // the resolution indicator (TravellingWaveBranch::defects) and the largest mesh used
    wave["max_defect"] = num(w.max_defect);
    wave["intervals_used"] = w.branch.intervals;
    for (std::size_t i = 0; i < w.branch.points.size() && i < w.defects.size(); ++i) j["points"][i]["defect"] = num(w.defects[i]);
    j["wave"] = wave;
    return text(j);
}


std::string design_json(const DesignResult& r, double margin) {
    JsonObject gains, initial_gains, bounds;
    for (const auto& [k, v] : r.gains) gains.number(k, v);
    for (const std::string& k : r.free) initial_gains.number(k, r.initial.at(k));
    for (const BoundedParameter& b : r.bounds) bounds.json(b.name, "[" + json_number(b.lower) + "," + json_number(b.upper) + "]");
    std::string at_bound = "[";
    for (std::size_t i = 0; i < r.at_bound.size(); ++i) at_bound += (i ? "," : "") + json_string(r.at_bound[i]);
    at_bound += "]";
    std::string starts = "[";
    for (std::size_t i = 0; i < r.starts.size(); ++i) {
        const DesignStart& s = r.starts[i];
        JsonObject o;
        std::vector<std::string> path;
        for (const ParameterMap& q : s.path) path.push_back(json_parameters(q));
        o.string("objective_name", s.objective).json("start", json_parameters(s.start)).json("end", json_parameters(s.end)).number("objective", s.value).string("status", to_string(s.status));
        o.json("path", json_array(path));
        o.string("message", s.message).integer("iterations", s.iterations).integer("evaluations", s.evaluations);
        starts += (i ? "," : "") + o.str();
    }
    starts += "]";
    auto side = [&](const ParameterMap& g, double value, const AttenuationScan& a, const StringResult& s, const std::optional<RingResult>& ring) {
        JsonObject o;
        o.json("gains", json_parameters(g)).number("objective", value);
        if (s.plant_stable) o.number("attenuation_margin", a.margin);
        else o.null("attenuation_margin");
        o.json("verdicts", string_json(s, ring ? &*ring : nullptr));
        return o.str();
    };
    JsonObject res;
    res.string("objective_name", r.objective).number("objective", r.value).json("gains", gains.str()).json("parameters", json_parameters(r.parameters));
    res.json("bounds", bounds.str()).json("at_bound", at_bound).number("change", r.change);
    res.number("margin", margin);
    if (r.string.plant_stable) res.number("attenuation_margin", r.attenuation.margin);
    else res.null("attenuation_margin");
    res.boolean("margin_met", r.margin_met);
    if (r.infeasibility_proof.empty()) res.null("infeasibility_proof");
    else res.string("infeasibility_proof", r.infeasibility_proof);
    res.json("verdicts", string_json(r.string, r.ring ? &*r.ring : nullptr));
    ParameterMap ig;
    for (const std::string& k : r.free) ig[k] = r.initial.at(k);
    res.json("initial", side(ig, r.value_initial, r.attenuation_initial, r.string_initial, r.ring_initial));
    res.string("method", r.method).integer("evaluations", r.evaluations).json("starts", starts);
    if (r.has_uncertainty) {
        // the probability of string stability under the fit's uncertainty of the held parameters
        auto prob = [](const VerdictUncertainty& u) {
            JsonObject o;
            const ProbabilityEstimate& e = u.string_unstable;
            o.number("p_string_stable", 1.0 - e.p).number("standard_error", e.standard_error);
            o.json("wilson", "[" + json_number(1.0 - e.upper) + "," + json_number(1.0 - e.lower) + "]");
            o.integer("samples", u.samples).integer("undecided", u.undecided).string("status", to_string(u.status));
            return o.str();
        };
        // the least attenuation margin over the fit's 95 % ellipsoid of the held parameters
        // (null: a plant unstable there)
        auto worst = [](const WorstMargin& w) {
            JsonObject o;
            if (std::isfinite(w.margin)) o.number("attenuation_margin", w.margin);
            else o.null("attenuation_margin");
            o.number("nominal", w.nominal).json("at", json_parameters(w.at));
            std::vector<std::string> held;
            for (const auto& h : w.held) held.push_back(json_string(h));
            o.json("held", json_array(held)).number("radius2", w.radius2).boolean("plant_unstable", w.plant_unstable).integer("evaluations", w.evaluations);
            return o.str();
        };
        res.json("uncertainty", JsonObject()
                                    .json("design", prob(r.uncertainty))
                                    .json("initial", prob(r.uncertainty_initial))
                                    .json("worst_case", JsonObject().json("design", worst(r.worst)).json("initial", worst(r.worst_initial)).str())
                                    .str());
        if (r.robust) {
            // the exchange method: the held values each design added (the car's own first), its gains and worst margin
            std::vector<std::string> steps;
            for (const auto& st : r.robust_steps) {
                JsonObject so;
                so.json("scenario", json_parameters(st.scenario)).json("gains", json_parameters(st.gains));
                if (std::isfinite(st.worst_margin)) so.number("worst_margin", st.worst_margin);
                else so.null("worst_margin");
                steps.push_back(so.str());
            }
            res.json("robust", JsonObject().boolean("met", r.robust_met).json("steps", json_array(steps)).str());
        }
    } else {
        res.null("uncertainty");
    }
    if (!r.robust) res.null("robust");
    return res.str();
}


JsonEnvelope design_envelope(const DesignResult& r, const DesignOptions& o, const std::string& car, const std::string& name) {
    JsonEnvelope e;
    e.command = "design";
    std::string free = "[";
    for (std::size_t i = 0; i < o.free.size(); ++i) free += (i ? "," : "") + json_string(o.free[i]);
    JsonObject in;
    in.string("car", car).string("name", name).string("model", r.model).json("parameters", json_parameters(r.initial));
    in.string("objective", r.objective).json("free", free + "]").number("margin", o.margin).integer("starts", o.starts);
    if (o.robust) in.boolean("robust", true);
    if (o.cars >= 0) in.json("ring", json_ring(o.cars));
    e.inputs = in.str();
    e.has_solver = true;
    e.solver_given = "auto";
    e.solver_used = r.method;
    e.status = to_string(r.status);
    e.message = r.message;
    e.result = design_json(r, o.margin);
    return e;
}

}  // namespace ddemap
