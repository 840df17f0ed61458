#include "ddemap/io/csv.hpp"

#include "core/internal/text.hpp"
#include "ddemap/analysis/design/design.hpp"
#include "ddemap/core/units.hpp"
#include "ddemap/traffic/model.hpp"

#include <algorithm>
#include <cmath>
#include <charconv>
#include <cstdio>
#include <stdexcept>
#include <limits>
#include <string>
#include <sstream>

namespace ddemap {

std::string format_exact(double v) {
    if (!std::isfinite(v)) throw std::logic_error("a non-finite number (" + std::to_string(v) + ") reached a CSV output");
    char b[40];
    const auto r = std::to_chars(b, b + sizeof b, v == 0.0 ? 0.0 : v);  // the shortest form that reads back exactly
    return std::string(b, r.ptr);
}

namespace {
/// A car parameter's column: its name with the unit of the built-in models (k1_per_s2, th_s).
std::string parameter_column(const std::string& name) { return column_name(name, parameter_unit(name)); }
}  // namespace

std::string named_column(const std::string& name, const ColumnUnits& units, const std::string& key) {
    const auto it = units.find(key.empty() ? name : key);
    return csv_field(column_name(name, it == units.end() ? std::string() : it->second));
}

std::string sweep_csv(const SweepResult& sw) {
    std::ostringstream s;
    s << parameter_column(sw.spec.x.name) << "," << parameter_column(sw.spec.y.name)
      << ",spectral_abscissa_per_s,unstable_roots,sup_gamma,omega_peak_rad_per_s,plant_stable,ring_stable,string_stable,"
         "abscissa_mode,plant_abscissa_per_s,lowfreq_margin,peak_gain,certified"
      << (sw.spec.peak ? ",peak_norm,peak_stable" : "") << "\n";
    auto b = [](bool v) { return v ? "true" : "false"; };
    for (const auto& p : sw.points) {
        s << format_exact(p.x) << "," << format_exact(p.y) << "," << format_exact(p.spectral_abscissa) << ",";
        if (p.unstable_roots >= 0) s << p.unstable_roots;
        s << "," << format_exact(p.sup_gamma) << "," << format_exact(p.omega_peak) << "," << b(p.plant_stable) << ","
          << b(p.ring_stable) << "," << b(p.string_stable) << ",";
        if (p.abscissa_mode >= 0) s << p.abscissa_mode;
        s << "," << format_exact(p.plant_abscissa) << "," << format_exact(p.lowfreq_margin) << "," << format_exact(p.peak_gain)
          << "," << b(p.certified);
        // ||h||_1 where it was computed (L2-stable points with a stable plant); empty elsewhere
        if (sw.spec.peak) s << "," << (p.peak_norm > 0.0 && std::isfinite(p.peak_norm) ? format_exact(p.peak_norm) : std::string()) << "," << b(p.peak_stable);
        s << "\n";
    }
    return s.str();
}

std::string boundary_csv(const SweepSpec& spec, const BoundarySet& set) {
    std::ostringstream s;
    s << "branch,kind,subkind,mode," << parameter_column(spec.x.name) << "," << parameter_column(spec.y.name) << ",omega_rad_per_s\n";
    for (std::size_t i = 0; i < set.curves.size(); ++i) {
        const auto& c = set.curves[i];
        for (const auto& p : c.points) {
            s << i + 1 << "," << kind_name(c.kind) << "," << subkind_name(c.kind) << ",";
            if (c.kind == BoundaryKind::RingHopf) s << c.mode;
            s << "," << format_exact(p.x) << "," << format_exact(p.y) << "," << format_exact(p.omega) << "\n";
        }
    }
    return s.str();
}

namespace {
const char* tf(bool v) { return v ? "true" : "false"; }
}  // namespace

std::string csv_field(const std::string& text) {
    // UTF-8 out whatever comes in (the readers refuse names that are not); quoted when it holds
    // a separator, a quote or a line end, or starts with '#' (a comment line to the readers)
    const std::string s = detail::utf8_replaced(text);
    if (s.find_first_of(",\"\n\r") == std::string::npos && (s.empty() || s[0] != '#')) return s;
    std::string out = "\"";
    for (char c : s) {
        if (c == '"') out += '"';
        out += c;
    }
    return out + "\"";
}

std::string equilibrium_branch_csv(const EquilibriumBranch& b, const std::vector<std::string>& variables, const ColumnUnits& units) {
    std::string out = "kind," + named_column(b.parameter, units);
    for (const auto& v : variables) out += "," + named_column(v, units);
    out += ",abscissa_per_s,unstable,stable,omega_rad_per_s,status\n";
    auto xs = [](const Eigen::VectorXd& x) {
        std::string s;
        for (Eigen::Index i = 0; i < x.size(); ++i) s += "," + format_exact(x[i]);
        return s;
    };
    for (const EquilibriumPoint& p : b.points) {
        // where the roots did not converge there is no verdict: empty abscissa, count and stability
        const bool decided = p.roots_status == Status::Converged && std::isfinite(p.abscissa);
        out += "point," + format_exact(p.par) + xs(p.x) + "," + (decided ? format_exact(p.abscissa) : std::string()) + "," +
               (decided ? std::to_string(p.unstable) : std::string()) + "," + (!decided ? "" : p.stable ? "true" : "false") + ",," +
               to_string(p.roots_status) + "\n";
    }
    for (const FoldPoint& f : b.folds) out += f.kind + "," + format_exact(f.par) + xs(f.x) + ",,,,," + to_string(f.status) + "\n";
    for (const HopfPoint& h : b.hopf)
        out += "hopf," + format_exact(h.par) + xs(h.x) + ",,,," + format_exact(h.omega) + "," + to_string(h.status) + "\n";
    return out;
}

std::string fold_curves_csv(const FoldCurves& c, const std::string& parameter2, const std::vector<std::string>& variables, const ColumnUnits& units) {
    std::string out = "curve,kind," + named_column(c.start.parameter, units) + "," + named_column(parameter2, units);
    for (const auto& v : variables) out += "," + named_column(v, units);
    out += ",cusp_test,bt_test,unstable,omega_rad_per_s,residual,status,nf_a,nf_b,nf_c\n";
    auto finite = [](double v) { return std::isfinite(v) ? format_exact(v) : std::string(); };
    auto xs = [&](const Eigen::VectorXd& x) {
        std::string s;
        for (std::size_t i = 0; i < variables.size(); ++i) s += "," + (static_cast<Eigen::Index>(i) < x.size() ? finite(x[static_cast<Eigen::Index>(i)]) : std::string());
        return s;
    };
    for (std::size_t k = 0; k < c.curves.size(); ++k) {
        for (const FoldCurvePoint& p : c.curves[k].points)
            out += std::to_string(k) + ",point," + format_exact(p.par) + "," + format_exact(p.par2) + xs(p.x) + "," + finite(p.cusp_test) + "," +
                   finite(p.bt_test) + "," + (p.unstable >= 0 ? std::to_string(p.unstable) : std::string()) + ",," + finite(p.residual) + ",,,,\n";
        for (const FoldCurveSpecialPoint& p : c.curves[k].special)
            out += std::to_string(k) + "," + p.kind + "," + format_exact(p.par) + "," + format_exact(p.par2) + xs(p.x) + ",,,," +
                   (p.kind == "zero_hopf" ? finite(p.omega) : std::string()) + "," + finite(p.residual) + "," + to_string(p.status) + "," +
                   finite(p.nf_a) + "," + finite(p.nf_b) + "," + finite(p.nf_c) + "\n";
    }
    return out;
}

std::string orbit_branch_csv(const OrbitBranch& b, const std::vector<std::string>& variables, const ColumnUnits& units) {
    std::string out = "kind," + named_column(b.parameter, units) + ",period_s,stable,trivial_distance,max_nontrivial";
    for (const auto& v : variables) out += "," + named_column("min_" + v, units, v);
    for (const auto& v : variables) out += "," + named_column("max_" + v, units, v);
    out += "\n";
    const std::string empty_extremes(2 * variables.size(), ',');
    auto finite = [](double v) { return std::isfinite(v) ? format_exact(v) : std::string(); };
    auto row = [&](const std::string& kind, const PeriodicOrbit& p) {
        std::string r = kind + "," + format_exact(p.par) + "," + format_exact(p.period) + "," + (p.multipliers.empty() || !p.undecided.empty() ? "" : p.stable ? "true" : "false") +
                        "," + finite(p.trivial_distance) + "," + finite(p.max_nontrivial);
        for (Eigen::Index i = 0; i < p.min.size(); ++i) r += "," + format_exact(p.min[i]);
        for (Eigen::Index i = 0; i < p.max.size(); ++i) r += "," + format_exact(p.max[i]);
        return r + "\n";
    };
    for (const PeriodicOrbit& p : b.points) out += row("orbit", p);
    for (const OrbitFold& f : b.folds) out += row("fold", f.orbit);
    for (const OrbitCrossing& x : b.period_doublings) out += "period_doubling," + format_exact(x.par) + "," + format_exact(x.period) + ",,," + empty_extremes + "\n";
    for (const OrbitCrossing& x : b.tori) out += "torus," + format_exact(x.par) + "," + format_exact(x.period) + ",,," + empty_extremes + "\n";
    return out;
}

std::string orbit_fold_curves_csv(const std::vector<OrbitFoldCurve>& curves, const std::vector<std::string>& variables, const ColumnUnits& units) {
    if (curves.empty()) return "curve\n";
    std::string out = "curve," + named_column(curves.front().parameter, units) + "," + named_column(curves.front().parameter2, units) +
                      ",period_s,fold_test,second_distance";
    bool torus = false;  // torus curves (any point with a rotation)
    for (const OrbitFoldCurve& c : curves)
        for (const OrbitFoldCurvePoint& q : c.points) torus = torus || std::isfinite(q.rotation);
    if (torus) out += ",rotation_rad";
    for (const auto& v : variables) out += "," + named_column("min_" + v, units, v);
    for (const auto& v : variables) out += "," + named_column("max_" + v, units, v);
    out += "\n";
    for (std::size_t k = 0; k < curves.size(); ++k)
        for (const OrbitFoldCurvePoint& q : curves[k].points) {
            out += std::to_string(k) + "," + format_exact(q.par) + "," + format_exact(q.par2) + "," + format_exact(q.orbit.period) + "," +
                   format_exact(q.test) + "," + (std::isfinite(q.second_distance) ? format_exact(q.second_distance) : std::string());
            if (torus) out += "," + (std::isfinite(q.rotation) ? format_exact(q.rotation) : std::string());
            for (Eigen::Index i = 0; i < q.orbit.min.size(); ++i) out += "," + format_exact(q.orbit.min[i]);
            for (Eigen::Index i = 0; i < q.orbit.max.size(); ++i) out += "," + format_exact(q.orbit.max[i]);
            out += "\n";
        }
    return out;
}

std::string roots_csv(const std::vector<Root>& roots) {
    std::string out = "re_per_s,im_rad_per_s,residual,newton_step_per_s\n";
    for (const auto& x : roots)
        out += format_exact(x.value.real()) + "," + format_exact(x.value.imag()) + "," + format_exact(x.residual) + "," +
               format_exact(x.newton_step) + "\n";
    return out;
}

std::string ring_roots_csv(const RingResult& r) {
    std::ostringstream out;
    out << "mode,theta_rad,re_per_s,im_rad_per_s,residual,newton_step_per_s\n";
    for (const auto& x : r.roots) {
        out << (x.mode < 0 ? std::string() : std::to_string(x.mode)) << "," << format_exact(x.theta) << ","
            << format_exact(x.root.value.real()) << "," << format_exact(x.root.value.imag()) << ","
            << format_exact(x.root.residual) << "," << format_exact(x.root.newton_step) << "\n";
    }
    return out.str();
}

namespace {
/// ",VERDICT,NORM,ERROR": an infinite or undecided norm is an empty field (never inf or nan)
std::string peak_fields(const PeakResult& p) {
    const bool value = p.verdict != Verdict::Undecided && p.finite;
    return "," + to_string(p.verdict) + "," + (value ? format_exact(p.norm) : std::string()) + "," + (value ? format_exact(p.error) : std::string());
}
}  // namespace

std::string string_csv(const StringResult& s, const RingResult* ring) {
    std::ostringstream out;
    out << "plant_stable,plant_abscissa_per_s,sup_gamma,omega_peak_rad_per_s,peak_margin,lowfreq_margin,string_stable";
    if (ring) out << ",ring,ring_stable,spectral_abscissa_per_s";
    if (s.peak) out << ",peak_verdict,peak_norm,peak_norm_error";
    out << "\n";
    out << tf(s.plant_stable) << "," << format_exact(s.plant_abscissa) << "," << format_exact(s.sup_gamma) << ","
        << format_exact(s.omega_peak) << "," << format_exact(s.peak_margin) << "," << format_exact(s.lowfreq_margin) << ","
        << tf(s.string_stable);
    if (ring)
        out << "," << (ring->cars == 0 ? std::string("inf") : std::to_string(ring->cars)) << "," << tf(ring->stable) << ","
            << format_exact(ring->spectral_abscissa);
    if (s.peak) out << peak_fields(*s.peak);
    out << "\n";
    return out.str();
}

std::string classification_csv(const std::vector<Classification>& rows) {
    std::ostringstream out;
    out << "name";
    for (const char* k : {"k1", "k2", "th", "tau", "eta"}) out << "," << parameter_column(k);
    out << ",plant_stable,ring_stable,string_stable,sup_gamma,omega_peak_rad_per_s,lowfreq_margin,"
           "spectral_abscissa_per_s,plant_abscissa_per_s,attenuation_margin_s";
    // the verdicts under parameter uncertainty, only when a vehicle carries a covariance
    const bool any = std::any_of(rows.begin(), rows.end(), [](const Classification& r) { return r.has_uncertainty; });
    if (any)
        out << ",p_string_unstable,p_string_unstable_se,p_string_unstable_lower,p_string_unstable_upper,c2_lower_per_s2,c2_upper_per_s2,"
               "sup_gamma_minus_1_lower,sup_gamma_minus_1_upper,spectral_abscissa_lower_per_s,spectral_abscissa_upper_per_s,samples";
    // peak (L-infinity) string stability, when it was asked (classify --peak): the last columns
    const bool peak = std::any_of(rows.begin(), rows.end(), [](const Classification& r) { return r.string.peak.has_value(); });
    if (peak) out << ",peak_verdict,peak_norm,peak_norm_error";
    // the distance to the other verdict, when it was asked (classify --distance)
    const bool dist = std::any_of(rows.begin(), rows.end(), [](const Classification& r) { return r.has_distance; });
    if (dist) out << ",verdict_distance,verdict_distance_boundary,verdict_distance_omega_rad_per_s";
    out << "\n";
    for (const auto& row : rows) {
        out << csv_field(row.vehicle.name);
        for (const char* k : {"k1", "k2", "th", "tau", "eta"}) out << "," << format_exact(row.vehicle.parameters.at(k));
        out << "," << tf(row.string.plant_stable) << "," << tf(row.ring.stable) << "," << tf(row.string.string_stable) << ","
            << format_exact(row.string.sup_gamma) << "," << format_exact(row.string.omega_peak) << ","
            << format_exact(row.string.lowfreq_margin) << "," << format_exact(row.ring.spectral_abscissa) << ","
            << format_exact(row.string.plant_abscissa) << ","
            << (std::isfinite(row.attenuation_margin) ? format_exact(row.attenuation_margin) : std::string());
        if (any && row.has_uncertainty) {
            const VerdictUncertainty& u = row.uncertainty;
            for (double v : {u.string_unstable.p, u.string_unstable.standard_error, u.string_unstable.lower, u.string_unstable.upper,
                             u.c2.lower, u.c2.upper, u.sup_gamma_excess.lower, u.sup_gamma_excess.upper})
                out << "," << format_exact(v);
            if (u.ring_unstable.trials > 0) out << "," << format_exact(u.ring_abscissa.lower) << "," << format_exact(u.ring_abscissa.upper);
            else out << ",,";
            out << "," << u.samples;
        } else if (any) {
            out << ",,,,,,,,,,,";
        }
        if (peak) out << (row.string.peak ? peak_fields(*row.string.peak) : std::string(",,,"));
        if (dist) {
            const bool ok = row.has_distance && row.distance.status == Status::Converged;
            out << "," << (ok ? format_exact(row.distance.distance) : std::string()) << "," << (ok ? row.distance.boundary : std::string()) << ","
                << (ok && std::isfinite(row.distance.omega) ? format_exact(row.distance.omega) : std::string());
        }
        out << "\n";
    }
    return out.str();
}

std::string simulation_csv(const SimResult& r) {
    std::ostringstream csv;
    csv << "time_s,car,position_m,speed_mps,gap_m\n";
    for (std::size_t k = 0; k < r.time.size(); ++k)
        for (std::size_t c = 0; c < r.speed.size(); ++c) {
            csv << format_exact(r.time[k]) << "," << c << "," << format_exact(r.position[c][k]) << "," << format_exact(r.speed[c][k]) << ",";
            if (c > 0) csv << format_exact(r.gap[c][k]);
            csv << "\n";
        }
    return csv.str();
}

std::string growth_csv(const std::vector<GrowthResult>& g) {
    std::ostringstream out;
    out << "name,position,speed_drop_mps,amplification,min_gap_m,failure\n";
    for (const auto& r : g) {
        for (std::size_t i = 0; i < r.amplification.size(); ++i) {
            out << r.name << "," << i + 1 << "," << format_exact(r.speed_drop[i]) << "," << format_exact(r.amplification[i]) << ","
                << format_exact(r.min_gap[i]) << "," << (r.status == Status::Converged ? "" : to_string(r.status)) << "\n";
        }
        if (r.failed_at) {
            out << r.name << "," << r.failed_at << ",," << format_exact(r.failure_amplification) << "," << format_exact(r.failure_gap)
                << "," << r.failure << "\n";
        }
    }
    return out.str();
}

std::string calibration_csv(const std::vector<std::string>& names, const std::vector<CalibrationResult>& fits,
                            const CalibrationOptions& options) {
    std::ostringstream csv;
    csv << "name";
    for (const char* k : {"k1", "k2", "th", "tau", "eta"}) csv << "," << parameter_column(k);
    csv << ",rmse_speed_mps,rmse_gap_m,train_rmse_speed_mps,train_rmse_gap_m,test_rmse_speed_mps,test_rmse_gap_m,naive_rmse_speed_mps,status";
    // the covariance (upper triangle, the columns `classify` reads); empty cells when the trace
    // does not determine a parameter (an infinite standard error: the covariance understates it)
    for (const auto& c : covariance_column_names()) csv << "," << c;
    // the bounds the fit searched within (classify restricts its parameter samples to them)
    for (const auto& c : bounds_column_names()) csv << "," << c.substr(0, 3) << parameter_column(c.substr(3));
    csv << "\n";
    std::string bounds;
    for (const auto& name : calibration_parameter_names()) {
        const BoundedParameter b = options.bound(name);
        bounds += "," + format_exact(b.lower) + "," + format_exact(b.upper);
    }
    for (std::size_t i = 0; i < fits.size(); ++i) {
        const auto& r = fits[i];
        csv << csv_field(i < names.size() ? names[i] : std::string());
        for (const char* k : {"k1", "k2", "th", "tau", "eta"}) csv << "," << format_exact(r.parameters.at(k));
        csv << "," << format_exact(r.all.rmse_speed) << "," << format_exact(r.all.rmse_gap) << "," << format_exact(r.train.rmse_speed)
            << "," << format_exact(r.train.rmse_gap) << ",";
        if (r.test.samples > 0) csv << format_exact(r.test.rmse_speed) << "," << format_exact(r.test.rmse_gap);
        else csv << ",";
        csv << "," << format_exact(r.naive.rmse_speed) << "," << r.status;
        bool determined = r.covariance.allFinite();
        for (const auto& e : r.estimates) determined = determined && std::isfinite(e.standard_error);
        for (int a = 0; a < 5; ++a)
            for (int b = a; b < 5; ++b) csv << "," << (determined ? format_exact(r.covariance(a, b)) : std::string());
        csv << bounds << "\n";
    }
    return csv.str();
}

std::string mix_csv(const std::vector<MixPoint>& points) {
    std::ostringstream csv;
    csv << "p,x_cars,spectral_abscissa_per_s,spectral_abscissa_min_per_s,spectral_abscissa_max_per_s,speed_mps,ring_stable,unstable_roots,"
           "arrangements,max_residual,status\n";
    for (const auto& pt : points) {
        csv << format_exact(pt.fraction) << "," << pt.x_cars << "," << format_exact(pt.abscissa) << "," << format_exact(pt.abscissa_min)
            << "," << format_exact(pt.abscissa_max) << "," << format_exact(pt.speed) << "," << tf(pt.stable) << ","
            << pt.unstable_roots << "," << pt.arrangements << "," << format_exact(pt.max_residual) << "," << to_string(pt.status)
            << "\n";
    }
    return csv.str();
}


std::string design_csv(const DesignResult& r) {
    std::ostringstream out;
    out << "point";
    for (const std::string& k : r.free) out << "," << csv_field(parameter_column(k));
    out << "," << column_name("objective", r.objective == "abscissa" ? "1/s" : "")
        << ",attenuation_margin_s,sup_gamma,peak_norm,plant_stable,string_stable,peak_stable,plant_abscissa_per_s\n";
    auto row = [&](const std::string& name, const ParameterMap& p, double value, const AttenuationScan& a, const StringResult& s) {
        out << name;
        for (const std::string& k : r.free) out << "," << format_exact(p.at(k));
        out << "," << (std::isfinite(value) ? format_exact(value) : std::string("inf"));
        out << "," << (s.plant_stable ? format_exact(a.margin) : std::string());
        out << "," << format_exact(s.sup_gamma);
        out << "," << (s.peak && s.peak->finite ? format_exact(s.peak->norm) : std::string());
        out << "," << (s.plant_stable ? "true" : "false") << "," << (s.string_stable ? "true" : "false") << ","
            << (s.peak && s.peak->verdict == Verdict::Stable ? "true" : "false") << "," << format_exact(s.plant_abscissa) << "\n";
    };
    row("car", r.initial, r.value_initial, r.attenuation_initial, r.string_initial);
    row("design", r.parameters, r.value, r.attenuation, r.string);
    return out.str();
}
}  // namespace ddemap
