#include "ddemap/io/hopf_output.hpp"

#include <cmath>

#include <nlohmann/json.hpp>

#include "ddemap/io/csv.hpp"
#include "ddemap/io/json.hpp"
#include "io/internal/json_values.hpp"

namespace ddemap {

namespace {

using json = nlohmann::ordered_json;

const auto num = detail::json_value;
const auto vec = detail::json_values;
std::string exact(double v) { return std::isfinite(v) ? format_exact(v) : std::string(); }

json point_json(const HopfCoefficients& c) {
    const bool ok = converged(c.status);
    json o;
    o["par"] = num(c.par);
    o["omega"] = num(c.omega);
    o["l1"] = ok ? num(c.l1) : json(nullptr);
    o["criticality"] = criticality_word(c);
    o["status"] = to_string(c.status);
    o["equilibrium"] = vec(c.x);
    o["dre_dpar"] = ok ? num(c.dre_dpar) : json(nullptr);
    o["side"] = c.side > 0 ? json("above") : c.side < 0 ? json("below") : json(nullptr);
    o["amplitude_coefficient"] = c.amplitude_coefficient.size() > 0 ? vec(c.amplitude_coefficient) : json(nullptr);
    o["c1"] = ok ? json::array({num(c.c1.real()), num(c.c1.imag())}) : json(nullptr);
    o["residual"] = num(c.residual);
    o["message"] = c.message;
    return o;
}

}  // namespace

std::string criticality_word(const HopfCoefficients& c) { return converged(c.status) ? to_string(c.criticality) : "undecided"; }

std::string hopf_points_json(const HopfAnalysis& a, const std::vector<std::string>& variables) {
    json j;
    j["parameter"] = a.branch.parameter;
    j["variables"] = variables;
    json hopf = json::array();
    for (const HopfCoefficients& c : a.points) hopf.push_back(point_json(c));
    j["hopf"] = hopf;
    json branch;
    branch["points"] = a.branch.points.size();
    branch["stop"] = to_string(a.branch.stop);
    branch["status"] = to_string(a.branch.status);
    branch["message"] = a.branch.message;
    j["branch"] = branch;
    return detail::json_text(j);
}

std::string hopf_points_csv(const HopfAnalysis& a, const std::vector<std::string>& variables, const ColumnUnits& units) {
    std::string out = named_column(a.branch.parameter, units) + ",omega_rad_per_s,l1,criticality,dre_dpar,side";
    for (const auto& v : variables) out += "," + named_column(v, units);
    for (const auto& v : variables) out += "," + csv_field("amp_" + v);
    out += ",residual,status\n";
    for (const HopfCoefficients& c : a.points) {
        const bool ok = converged(c.status);
        out += exact(c.par) + "," + exact(c.omega) + "," + (ok ? exact(c.l1) : "") + "," + criticality_word(c) + "," + (ok ? exact(c.dre_dpar) : "") +
               "," + (c.side > 0 ? "above" : c.side < 0 ? "below" : "");
        for (Eigen::Index i = 0; i < static_cast<Eigen::Index>(variables.size()); ++i) out += "," + (i < c.x.size() ? exact(c.x[i]) : "");
        for (Eigen::Index i = 0; i < static_cast<Eigen::Index>(variables.size()); ++i)
            out += "," + (i < c.amplitude_coefficient.size() ? exact(c.amplitude_coefficient[i]) : "");
        out += "," + exact(c.residual) + "," + to_string(c.status) + "\n";
    }
    return out;
}

std::string hopf_curves_json(const HopfCurves& hc, const std::string& parameter2, const std::vector<std::string>& variables) {
    json j;
    j["parameter"] = hc.start.branch.parameter;
    j["parameter2"] = parameter2;
    j["variables"] = variables;
    json hopf = json::array();
    for (const HopfCoefficients& c : hc.start.points) hopf.push_back(point_json(c));
    j["hopf"] = hopf;
    json curves = json::array();
    for (const HopfCurve& c : hc.curves) {
        json o = detail::curve_json(c.start, c.status, c.message, c.stop_backward, c.stop_forward);
        json pts = json::array();
        for (const HopfCurvePoint& p : c.points) {
            const bool ok = converged(p.coefficients.status);
            json q;
            q["par"] = num(p.par);
            q["par2"] = num(p.par2);
            q["omega"] = num(p.omega);
            q["l1"] = ok ? num(p.coefficients.l1) : json(nullptr);
            q["criticality"] = criticality_word(p.coefficients);
            q["dre_dpar"] = ok ? num(p.coefficients.dre_dpar) : json(nullptr);
            pts.push_back(q);
        }
        o["points"] = pts;
        json gh = json::array();
        for (const GeneralisedHopfPoint& g : c.generalised) {
            json q;
            q["par"] = num(g.par);
            q["par2"] = num(g.par2);
            q["omega"] = num(g.omega);
            q["l1"] = num(g.l1);
            q["l2"] = g.normal_form.status == Status::Converged ? num(g.normal_form.l2) : json(nullptr);
            q["status"] = to_string(g.status);
            q["normal_form"] = detail::generalised_hopf_normal_form_json(g.normal_form);
            if (converged(g.status) && g.normal_form.status != Status::Converged) q["normal_form_message"] = g.normal_form.message;
            gh.push_back(q);
        }
        o["generalised_hopf"] = gh;
        json dh = json::array();
        for (const DoubleHopfPoint& d : c.double_hopf) {
            json q;
            q["par"] = num(d.par);
            q["par2"] = num(d.par2);
            q["omega1"] = num(d.omega1);
            q["omega2"] = num(d.omega2);
            q["residual"] = num(d.residual);
            q["other_curve"] = d.other_curve;
            q["resonant_1_1"] = d.resonant;
            q["status"] = to_string(d.status);
            q["message"] = d.message;
            q["normal_form"] = detail::double_hopf_normal_form_json(d.normal_form);
            if (converged(d.status) && !d.resonant && d.normal_form.status != Status::Converged) q["normal_form_message"] = d.normal_form.message;
            dh.push_back(q);
        }
        o["double_hopf"] = dh;
        json zh = json::array();
        for (const ZeroHopfPoint& z : c.zero_hopf) {
            json q;
            q["par"] = num(z.par);
            q["par2"] = num(z.par2);
            q["omega"] = num(z.omega);
            q["det_delta0"] = num(z.det);
            q["residual"] = num(z.residual);
            q["status"] = to_string(z.status);
            q["normal_form"] = detail::zero_hopf_normal_form_json(z.normal_form);
            if (z.normal_form.status != Status::Converged) q["normal_form_message"] = z.normal_form.message;
            zh.push_back(q);
        }
        o["zero_hopf"] = zh;
        json bts = json::array();
        for (const HopfCurveBogdanovTakens& b : c.bogdanov_takens) {
            json q;
            q["par"] = num(b.par);
            q["par2"] = num(b.par2);
            q["end"] = b.forward ? "forward" : "backward";
            q["residual"] = num(b.residual);
            q["status"] = to_string(b.status);
            q["message"] = b.message;
            q["normal_form"] = b.normal_form.status == Status::Converged ? json{{"a", num(b.normal_form.a)}, {"b", num(b.normal_form.b)}} : json(nullptr);
            bts.push_back(q);
        }
        o["bogdanov_takens"] = bts;
        json unstable = json::array();
        for (const HopfCurvePoint& p : c.points) unstable.push_back(p.unstable);
        o["unstable_beside_pair"] = unstable;
        curves.push_back(o);
    }
    j["curves"] = curves;
    return detail::json_text(j);
}

std::string hopf_curves_csv(const HopfCurves& hc, const std::string& parameter2, const ColumnUnits& units) {
    std::string out = "curve,kind," + named_column(hc.start.branch.parameter, units) + "," + named_column(parameter2, units) +
                      ",omega_rad_per_s,l1,criticality,status\n";
    for (std::size_t k = 0; k < hc.curves.size(); ++k) {
        const HopfCurve& c = hc.curves[k];
        for (const HopfCurvePoint& p : c.points) {
            const bool ok = converged(p.coefficients.status);
            out += std::to_string(k) + ",point," + exact(p.par) + "," + exact(p.par2) + "," + exact(p.omega) + "," + (ok ? exact(p.coefficients.l1) : "") +
                   "," + criticality_word(p.coefficients) + "," + to_string(p.coefficients.status) + "\n";
        }
        for (const GeneralisedHopfPoint& g : c.generalised)
            out += std::to_string(k) + ",generalised_hopf," + exact(g.par) + "," + exact(g.par2) + "," + exact(g.omega) + "," + exact(g.l1) +
                   ",degenerate," + to_string(g.status) + "\n";
        for (const DoubleHopfPoint& d : c.double_hopf)
            out += std::to_string(k) + ",double_hopf," + exact(d.par) + "," + exact(d.par2) + "," + exact(d.omega2) + ",,," + to_string(d.status) + "\n";
        for (const ZeroHopfPoint& z : c.zero_hopf)
            out += std::to_string(k) + ",zero_hopf," + exact(z.par) + "," + exact(z.par2) + "," + exact(z.omega) + ",,," + to_string(z.status) + "\n";
        for (const HopfCurveBogdanovTakens& b : c.bogdanov_takens)
            out += std::to_string(k) + ",bogdanov_takens," + exact(b.par) + "," + exact(b.par2) + ",0,,," + to_string(b.status) + "\n";
    }
    return out;
}

std::string bistability_json(const BistabilityChart& c, const std::vector<std::string>& variables) {
    json j;
    j["parameter"] = c.parameter;
    j["parameter2"] = c.parameter2;
    j["box"] = json::array({num(c.from), num(c.to), num(c.from2), num(c.to2)});
    j["hopf"] = json::parse(hopf_curves_json(c.hopf, c.parameter2, variables));
    j["fold_curves"] = json::parse(orbit_fold_curves_json(c.folds, variables));
    json cells = json::array();
    for (const BistabilityCell& k : c.cells) {
        json o;
        o["par"] = num(k.par);
        o["par2"] = num(k.par2);
        o["equilibrium_stable"] = k.equilibrium_stable;
        o["stable_orbit"] = k.stable_orbit;
        o["bistable"] = k.bistable;
        o["status"] = to_string(k.status);
        o["message"] = k.message;
        json iv = json::array();
        for (const auto& x : k.intervals) iv.push_back(json::array({num(x.par2), num(x.lo), num(x.hi)}));
        o["intervals"] = iv;
        cells.push_back(o);
    }
    j["cells"] = cells;
    j["slices"] = c.slices;
    j["rounds"] = c.rounds;
    return detail::json_text(j);
}

std::string bistability_csv(const BistabilityChart& c, const ColumnUnits& units) {
    std::string out = "curve,kind," + named_column(c.parameter, units) + "," + named_column(c.parameter2, units) + "\n";
    for (std::size_t k = 0; k < c.hopf.curves.size(); ++k) {
        for (const HopfCurvePoint& p : c.hopf.curves[k].points) {
            const HopfCoefficients& q = p.coefficients;
            const char* kind = !converged(q.status) ? "hopf" : q.l1 < 0.0 ? "hopf_supercritical" : q.l1 > 0.0 ? "hopf_subcritical" : "hopf";
            out += std::to_string(k) + "," + kind + "," + exact(p.par) + "," + exact(p.par2) + "\n";
        }
        for (const GeneralisedHopfPoint& g : c.hopf.curves[k].generalised)
            if (g.status == Status::Converged) out += std::to_string(k) + ",generalised_hopf," + exact(g.par) + "," + exact(g.par2) + "\n";
    }
    for (std::size_t k = 0; k < c.folds.size(); ++k)
        for (const OrbitFoldCurvePoint& p : c.folds[k].points) out += std::to_string(k) + ",fold_of_orbits," + exact(p.par) + "," + exact(p.par2) + "\n";
    return out;
}

}  // namespace ddemap
