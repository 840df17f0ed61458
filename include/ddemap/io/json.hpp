#pragma once
/// \file json.hpp
/// JSON writers (formatting only), shared by the command-line front and any other front end:
/// a small object builder, the one envelope of every command's JSON output, and the `result`
/// member of each analysis. Every builder returns JSON text; numbers are written so that they
/// read back to the same double, non-finite numbers as null. One set of key names for one
/// quantity: spectral_abscissa, ring_stable, string_stable, plant_stable, sup_gamma,
/// degree, degree_reason, status, ...

#include <string>
#include <utility>
#include <vector>

#include "ddemap/analysis/calibration/calibrate.hpp"
#include "ddemap/analysis/stability/classify.hpp"
#include "ddemap/analysis/bifurcation/equilibrium_branch.hpp"
#include "ddemap/analysis/bifurcation/fold_curve.hpp"
#include "ddemap/analysis/stability/mixed_ring.hpp"
#include "ddemap/analysis/bifurcation/periodic_orbit.hpp"
#include "ddemap/analysis/stability/ring_fast.hpp"
#include "ddemap/analysis/stability/ring_stability.hpp"
#include "ddemap/analysis/simulation/simulate.hpp"
#include "ddemap/analysis/stability/string_stability.hpp"
#include "ddemap/analysis/stability/system_roots.hpp"
#include "ddemap/analysis/bifurcation/travelling_wave.hpp"
#include "ddemap/problem/nonlinear_dde.hpp"
#include "ddemap/solve/equilibrium.hpp"
#include "ddemap/study/boundary.hpp"
#include "ddemap/study/growth.hpp"
#include "ddemap/study/penetration.hpp"
#include "ddemap/study/sweep.hpp"

namespace ddemap {

struct DesignResult;
struct DesignOptions;

/// A JSON object built key by key, keys in insertion order.
class JsonObject {
public:
    JsonObject& number(const std::string& key, double v);  ///< non-finite: null
    JsonObject& integer(const std::string& key, long long v);
    JsonObject& boolean(const std::string& key, bool v);
    JsonObject& string(const std::string& key, const std::string& v);
    JsonObject& null(const std::string& key);
    JsonObject& json(const std::string& key, const std::string& json_text);  ///< JSON text from another builder
    bool empty() const { return m_items.empty(); }
    std::string str() const;  ///< compact JSON text

private:
    std::vector<std::pair<std::string, std::string>> m_items;  // key, JSON text
};

/// The parameters of a nonlinear system other than the free one of a branch, by name with their
/// values, added to `o` (the inputs of equilibria, hopf, orbits). std::invalid_argument naming the
/// known parameters when `free_parameter` is not one of them.
JsonObject& add_held_parameters(JsonObject& o, const NonlinearDDE& system, const std::string& free_parameter);
/// {"x", "residual", "iterations", "status", "message"}: Newton's equilibrium of a nonlinear
/// system file (roots --system on a file with expressions).
std::string equilibrium_result_json(const EquilibriumResult& eq);

/// A JSON array of JSON texts.
std::string json_array(const std::vector<std::string>& items);
/// A JSON number (non-finite: null).
std::string json_number(double v);
/// A JSON string (quoted and escaped).
std::string json_string(const std::string& s);
/// A ring size: N, or "inf" for 0.
std::string json_ring(int cars);
/// A model's parameters as an object.
std::string json_parameters(const ParameterMap& p);

/// The one envelope of every command's JSON output:
/// {"command", "version", "inputs", "solver": {"given", "used"} or null, "status", "message", "result"}.
struct JsonEnvelope {
    std::string command;
    std::string inputs = "{}";       ///< JSON text: the parsed inputs
    bool has_solver = false;         ///< false: "solver": null (no solver choice)
    std::string solver_given, solver_used;
    std::string status = "converged";
    std::string message;
    std::string result = "{}";       ///< JSON text
};

/// Pretty-printed (indent 2) with a trailing newline.
std::string envelope_json(const JsonEnvelope& e);

// ------------------------------------------------------------------ results

/// roots of a ring of identical cars (analyse_ring)
std::string ring_roots_json(const RingResult& r);
/// roots of any linear DDE (analyse_system)
std::string system_roots_json(const LinearDDE& dde, const SystemRootResult& r);
/// an equilibrium branch: {"parameter", "variables", "points": [{"par", "x", "abscissa",
/// "unstable", "stable", "roots_status", "roots": [[re, im], ...]}], "folds": [{"kind" ("fold" or "branch_point"), "par", "x", "status",
/// "residual"}], "hopf": [{"par", "omega", "x", "status", "residual"}], "stop"}
std::string equilibrium_branch_json(const EquilibriumBranch& b, const std::vector<std::string>& variables);
/// fold curves in two parameters: {"parameter", "parameter2", "branch": equilibrium_branch_json
/// of the branch in p1, "curves": [{"start", "status", "message", "stop": [backward, forward],
/// "points": [{"par", "par2", "x", "cusp_test", "bt_test", "residual", "unstable"}], "special":
/// [{"kind" ("cusp", "bogdanov_takens" or "zero_hopf"), "par", "par2", "x", "omega" (zero_hopf),
/// "test", "other", "status", "residual", "after"}]}]}
std::string fold_curves_json(const FoldCurves& c, const std::string& parameter2, const std::vector<std::string>& variables);
/// roots of a mixed ring (analyse_mixed_ring)
std::string mixed_ring_json(const MixedRingResult& r, std::size_t cars);
/// string stability, with the ring verdict when `ring` is given
std::string string_json(const StringResult& s, const RingResult* ring);
/// The result of `design` (analysis/design/design.hpp): objective, gains, change, attenuation
/// margin, the certified verdicts at the design (`verdicts`, string_json's keys) and at the car
/// (`initial`), and every run (`starts`); `margin` is the margin asked for.
std::string design_json(const DesignResult& r, double margin);
/// The envelope of `design` for the car named `car` (as given) and `name` (its name), with the
/// options it ran with: inputs, solver {auto, the method used}, status, message, design_json.
JsonEnvelope design_envelope(const DesignResult& r, const DesignOptions& o, const std::string& car, const std::string& name);
/// {"ring_method", "listed_by", "winding": {...} or null} of analyse_ring_fast appended to a JSON
/// object's text (the result of roots or string for a ring of identical cars).
std::string append_ring_method_json(const std::string& object_text, const FastRing& f);
/// one object per vehicle: parameters, the three verdicts, sup_gamma, ...
std::string classification_json(const std::vector<Classification>& rows, int cars, const std::string& source);

/// The envelopes' `message` (why the result is trusted, or why not), one wording for the program
/// and the Python module: the first car, point, platoon or fit that is not converged and why;
/// otherwise what certifies the result.
std::string classification_message(const std::vector<Classification>& rows);
std::string sweep_message(const SweepResult& sweep);
std::string growth_message(const std::vector<GrowthResult>& g);
std::string mix_message(const std::vector<MixPoint>& points);
std::string calibration_message(const std::vector<std::string>& names, const std::vector<CalibrationResult>& fits);
/// the summary of a sweep (and its boundaries): inputs, method, degree, timings, region counts
std::string sweep_json(const SweepResult& sw, const BoundarySet* b);
/// the boundary curves' summary
std::string boundary_json(const BoundarySet& b);
/// a platoon simulation's summary: per car lowest_speed, speed_drop, min_gap, events
std::string simulation_json(const SimResult& r, const std::string& lead);
/// the growth study: per vehicle setting amplification by position and the failure
std::string growth_json(const std::vector<GrowthResult>& g, const std::string& lead);
/// calibration fits: {"fits": [...], "gap_weight", "bounds"}, always this shape (one fit per
/// file, or per car); with `cars` (fits[i] = cars[i].fit) each fit adds "train_runs" (file,
/// rmse_speed, rmse_gap, naive_rmse_speed, samples per fitted run) and "tests" (the same and
/// "type" per test run)
std::string calibration_json(const std::vector<std::string>& names, const std::vector<CalibrationResult>& fits,
                             const CalibrationOptions& options, const std::vector<CarCalibration>* cars = nullptr);
/// the penetration-rate study: one object per p
std::string mix_json(const std::vector<MixPoint>& points, int cars);

/// A branch of periodic orbits: {"parameter", "variables", "degree", "intervals", "points": [{"par",
/// "period", "min": [..], "max": [..], "stable", "multipliers": [[re, im], ..] (the largest
/// `multipliers` by modulus, the trivial one included), "trivial_distance", "residual"}],
/// "folds": [{"par", "period", "located"}], "period_doublings" and "tori": [{"par", "period",
/// "multiplier": [re, im]}], "stop", "method", "certificate": {"max_residual", "max_trivial_distance"}}.
std::string orbit_branch_json(const OrbitBranch& b, const std::vector<std::string>& variables, int multipliers = 10);
/// result.start of orbits started from a simulation run to t_end with step `step`: {"kind":
/// "simulation", "t_end", "step", "period", "crossings_per_period", "period_spread", "status", "message"}.
std::string simulation_start_json(const SimulatedOrbitGuess& g, double t_end, double step);
/// Curves of folds of periodic orbits in two parameters (orbit_fold_curve), an array: per curve
/// its parameters, points (par, par2, period, min, max of every variable, fold_test |g|,
/// second_distance |mu_2 - 1|, trivial_distance, residual; on torus curves also rotation, the
/// angle phi of the multipliers e^{+-i phi}), how each end ended, status, message, method and
/// certificate.
std::string orbit_fold_curves_json(const std::vector<OrbitFoldCurve>& curves, const std::vector<std::string>& variables);

/// A branch of travelling waves (analysis/travelling_wave.hpp): the keys of orbit_branch_json
/// (the variables are car 0's; "stable" is null where no multiplier was computed, i.e. N above
/// the full-ring limit: not decided) and "wave": {"cars", "wave", "shift" (k / N of the period),
/// "hopf": {"par", "omega", "status"}, "stability": "full_ring" | "not_computed", "max_drift"}.
std::string travelling_wave_json(const TravellingWaveBranch& w, const std::vector<std::string>& variables, int multipliers = 10);

}  // namespace ddemap
