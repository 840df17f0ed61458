// The compiled part of the Python module `ddemap` (ddemap._ddemap): one function per command,
// calling the same library functions as apps/cli and returning the command's JSON envelope
// (io/json.hpp: the same keys as `ddemap COMMAND --format json`); the grids of sweeps and the
// curves of boundaries also as NumPy arrays. python/ddemap/__init__.py turns the keyword
// arguments into these calls and the JSON into Python objects.
//
// Errors: std::invalid_argument (the library's bad-input errors) -> ValueError (pybind11's
// default translation, kept explicit here). Every computation runs with the GIL released; where
// the library reports progress (sweep rows, boundary seed rows, vehicles and samples of
// classify, simulated time, calibration fits, the points of equilibrium branches, Hopf curves and
// orbit branches, the contour counts, shifts and degrees of the roots of mixed rings and systems) the callback checks for Ctrl-C on the main thread and stops the computation
// (KeyboardInterrupt).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <tuple>
#include <utility>
#include <vector>

#include "ddemap/analysis/calibration/calibrate.hpp"
#include "ddemap/analysis/design/design.hpp"
#include "ddemap/analysis/design/verdict_distance.hpp"
#include "ddemap/analysis/stability/classify.hpp"
#include "ddemap/analysis/bifurcation/bistability.hpp"
#include "ddemap/analysis/bifurcation/equilibrium_branch.hpp"
#include "ddemap/analysis/bifurcation/fold_curve.hpp"
#include "ddemap/analysis/stability/mixed_ring.hpp"
#include "ddemap/analysis/stability/ring_stability.hpp"
#include "ddemap/analysis/simulation/simulate.hpp"
#include "ddemap/analysis/stability/string_stability.hpp"
#include "ddemap/analysis/stability/system_roots.hpp"
#include "ddemap/io/calibration_report.hpp"
#include "ddemap/io/files.hpp"
#include "ddemap/analysis/stability/ring_fast.hpp"
#include "ddemap/traffic/nonlinear_ring.hpp"
#include "ddemap/analysis/bifurcation/hopf.hpp"
#include "ddemap/analysis/bifurcation/periodic_orbit.hpp"
#include "ddemap/io/hopf_output.hpp"
#include <map>
#include "ddemap/io/csv.hpp"
#include "ddemap/io/json.hpp"
#include "ddemap/io/svg.hpp"
#include "ddemap/io/system_json.hpp"
#include "ddemap/io/cars.hpp"
#include "ddemap/io/chart_spec.hpp"
#include "ddemap/io/paper.hpp"
#include "ddemap/io/atlas.hpp"
#include "ddemap/study/atlas.hpp"
#include "builtin_maps.hpp"
#include "ddemap/problem/expression_system.hpp"
#include "ddemap/solve/equilibrium.hpp"
#include "ddemap/study/boundary.hpp"
#include "ddemap/study/growth.hpp"
#include "ddemap/study/penetration.hpp"
#include "ddemap/study/sweep.hpp"
#include "ddemap/traffic/fleet.hpp"
#include "ddemap/traffic/model.hpp"
#include "ddemap/traffic/vehicles.hpp"

namespace py = pybind11;
using namespace ddemap;

namespace {

/// Thrown by the progress callback when a signal handler raised (Ctrl-C: KeyboardInterrupt);
/// the Python error stays set and is what the caller sees. A ddemap::Cancelled, so the root
/// computations (rightmost_roots) return Status::Cancelled, turned back into it here.
struct Interrupted : Cancelled {
    const char* what() const noexcept override { return "interrupted"; }
};

std::thread::id g_main_thread;
/// The Python progress callback of the call in progress (set_progress; None: none), called on
/// the main thread with (done, total) at most 5 times a second. Never destroyed (it may outlive
/// the interpreter's teardown).
py::object* g_progress = nullptr;

/// A progress callback that runs the Python signal handlers between units of work (on the
/// main thread only: Python runs them nowhere else) and stops the computation if one raised.
Progress interruptible(bool report = true) {
    struct State {
        // the first unit of work on the main thread is checked and reported at once (a short call
        // reports too), the later ones at most 20 and 5 times a second
        std::chrono::steady_clock::time_point last = std::chrono::steady_clock::now() - std::chrono::milliseconds(50),
                                              reported = std::chrono::steady_clock::now() - std::chrono::milliseconds(200);
        std::atomic<bool> interrupted{false};
    };
    auto state = std::make_shared<State>();
    return [state, report](long done, long total) {
        // once interrupted, every later call throws, on any thread: nested loops (a loop whose
        // tasks run loops of their own) all stop
        if (state->interrupted.load()) throw Interrupted();
        if (std::this_thread::get_id() != g_main_thread) return;
        const auto now = std::chrono::steady_clock::now();
        if (now - state->last < std::chrono::milliseconds(50)) return;  // at most 20 checks a second
        state->last = now;
        py::gil_scoped_acquire gil;
        if (PyErr_CheckSignals() != 0) {
            state->interrupted.store(true);
            throw Interrupted();
        }
        if (report && g_progress && !g_progress->is_none() && now - state->reported >= std::chrono::milliseconds(200)) {
            state->reported = now;
            try {
                (*g_progress)(done, total);
            } catch (py::error_already_set& e) {  // the callback raised: its exception is what the caller sees
                e.restore();
                state->interrupted.store(true);
                throw Interrupted();
            }
        }
    };
}

/// The same for a branch (a continuation: equilibria, Hopf curves, periodic orbits), checked
/// after every point.
BranchProgress branch_interruptible() {
    return [check = interruptible()](long done, long total, double) { check(done, total); };
}

/// Runs `f` with the GIL released.
template <class F>
auto released(F&& f) {
    py::gil_scoped_release nogil;
    return f();
}

JsonObject model_inputs(const CarModel& m) {
    JsonObject o;
    o.string("model", m.name()).json("parameters", json_parameters(m.parameters()));
    return o;
}

std::string solver_name(const std::string& method) {
    if (method == "shift_invert") return "sparse";
    if (method == "contour") return "product";
    return method;
}

std::string root_method(const std::string& solver) {
    if (solver == "sparse") return "shift_invert";
    if (solver == "product") return "contour";
    if (solver == "auto" || solver == "dense" || solver == "shift_invert" || solver == "contour") return solver;
    throw std::invalid_argument("solver = '" + solver + "': expected auto, dense, sparse or product");
}

/// A car list (io/cars.hpp: built-in names, FILE.csv, FILE.csv:NAME, MODEL:k1=..., each with *K).
/// `tables`: tables in memory by the name the list uses for them (DataFrames, dicts, rows).
Fleet fleet_spec(const std::string& spec, const CarTables& tables = {}) { return to_fleet(read_cars(spec, kMaxCars, "", &tables)); }
std::vector<CalibratedVehicle> vehicles_spec(const std::string& spec, const CarTables& tables = {}) {
    std::vector<CalibratedVehicle> cars = read_cars(spec, kMaxCars, "", &tables);
    require_ovrv(cars, "the cars");
    return cars;
}

/// The lead of simulate and growth: a built-in profile by name (default dip), or a speed table or
/// car K of a platoon CSV, from a file or from text in memory named `file`; `label` names it as
/// the program does (FILE, FILE:K or the profile's name).
LeadProfile lead_from(const std::string& profile, const std::string& file, const std::string& text, int car, std::string& label) {
    if (!profile.empty() && !file.empty()) throw std::invalid_argument("give either lead (a CSV file) or lead_profile (a name), not both");
    if (!file.empty()) {
        label = car >= 0 ? file + ":" + std::to_string(car) : file;
        return LeadProfile::from_csv(text.empty() ? read_text_file(file) : text, file, car);
    }
    label = profile.empty() ? std::string("dip") : profile;
    const auto names = LeadProfile::builtin_names();
    if (std::find(names.begin(), names.end(), label) == names.end())
        throw std::invalid_argument("lead_profile = '" + label + "': expected one of dip, oscillatory, step-low, step-high");
    return LeadProfile::builtin(label);
}

// ------------------------------------------------------------------ commands

std::string py_roots(const std::string& model_name, const ParameterMap& values, int cars, int count) {
    const auto model = make_model(model_name, values);
    const Linearisation lin = model->linearise();
    // as the command: the verdict from one winding pass where it applies (analysis/ring_fast.hpp)
    const std::string method = resolve_ring_method("auto", lin);
    const Progress progress = interruptible();
    // N = inf: the search for the `count` roots at the abscissa's wave number checks too (its
    // dense degrees, and the stages within a long one)
    const BranchProgress search = branch_interruptible();
    const FastRing fast = released([&] { return analyse_ring_fast(lin, cars, method, count, progress, search); });
    const RingResult& r = fast.ring;
    JsonEnvelope e;
    e.command = "roots";
    e.inputs = model_inputs(*model).json("ring", json_ring(cars)).integer("count", count).string("ring_method", "auto").str();
    e.has_solver = true;
    e.solver_given = "auto";
    e.solver_used = fast.method_used;
    e.status = to_string(r.status);
    e.message = r.reason;
    e.result = append_ring_method_json(ring_roots_json(r), fast);
    return envelope_json(e);
}

/// roots --system FILE: any linear DDE, or a nonlinear one linearised at its equilibrium
/// (Newton from the file's guess), as the command.
std::string py_roots_system(const std::string& path, int count, int degree, const std::string& solver) {
    RootOptions o;
    o.count = count;
    o.degree = degree;
    o.method = root_method(solver);
    if (o.method == "contour") throw std::invalid_argument("solver = 'product' goes with fleet rings: expected auto, dense or sparse for a system");
    const std::string text = read_text_file(path);
    JsonEnvelope e;
    e.command = "roots";
    e.inputs = JsonObject().string("system", path).integer("count", o.count).integer("degree", o.degree).str();
    std::string equilibrium_json;
    std::optional<LinearDDE> lin;
    if (!is_nonlinear_system_json(text)) {
        lin.emplace(read_linear_dde_json(text, path));
    } else {
        const NonlinearSystemFile file = read_nonlinear_system_json(text, path);
        const EquilibriumResult eq = released([&] { return find_equilibrium(*file.system, file.equilibrium); });
        equilibrium_json = equilibrium_result_json(eq);
        if (!converged(eq.status)) {  // no equilibrium: undecided, the Newton result returned
            e.status = to_string(eq.status);
            e.message = "no equilibrium found from the guess";
            e.result = JsonObject().json("equilibrium", equilibrium_json).str();
            return envelope_json(e);
        }
        lin.emplace(linearise(*file.system, eq.x));
    }
    o.progress = branch_interruptible();
    const SystemRootResult sr = released([&] { return analyse_system(*lin, o); });
    if (sr.roots.status == Status::Cancelled) throw Interrupted();  // Ctrl-C: KeyboardInterrupt
    const RootResult& r = sr.roots;
    e.has_solver = true;
    e.solver_given = solver_name(r.method_given);
    e.solver_used = solver_name(r.method_used);
    e.status = to_string(r.status);
    e.message = r.message;
    e.result = system_roots_json(*lin, sr);
    if (!equilibrium_json.empty()) e.result = JsonObject().json("equilibrium", equilibrium_json).json("linearisation", e.result).str();
    return envelope_json(e);
}

std::string py_string(const std::string& model_name, const ParameterMap& values, std::optional<int> cars) {
    const auto model = make_model(model_name, values);
    const Linearisation lin = model->linearise();
    std::optional<RingResult> ring;
    std::optional<FastRing> fast;
    const std::string method = cars ? resolve_ring_method("auto", lin) : std::string();
    const Progress progress = interruptible();
    const StringResult s = released([&] {
        StringOptions so;
        so.peak = true;  // as the command: peak (L-infinity) string stability too
        StringResult r = analyse_string(lin, so);
        if (cars) {
            fast = analyse_ring_fast(lin, *cars, method, 0, progress);
            ring = fast->ring;
        }
        return r;
    });
    Status status = s.plant_roots.status;
    if (ring && ring->status != Status::Converged) status = ring->status;
    const bool peak_undecided = status == Status::Converged && s.peak->verdict == Verdict::Undecided;
    if (peak_undecided) status = s.peak->status;
    JsonEnvelope e;
    e.command = "string";
    JsonObject in = model_inputs(*model);
    if (cars) in.json("ring", json_ring(*cars)).string("ring_method", "auto");
    e.inputs = in.str();
    if (fast) {
        e.has_solver = true;
        e.solver_given = "auto";
        e.solver_used = fast->method_used;
    }
    e.status = to_string(status);
    e.message = ring && ring->status != Status::Converged ? ring->reason : peak_undecided ? s.peak->message : s.plant_roots.message;
    e.result = fast ? append_ring_method_json(string_json(s, ring ? &*ring : nullptr), *fast) : string_json(s, nullptr);
    return envelope_json(e);
}

SweepSpec sweep_spec(const std::string& model, const ParameterMap& fixed, const std::string& x_name, const std::string& x_text,
                     const std::string& y_name, const std::string& y_text, int cars) {
    SweepSpec spec;
    spec.model = model;
    spec.fixed = fixed;
    spec.x = parse_axis(x_name, x_text);
    spec.y = parse_axis(y_name, y_text);
    spec.cars = cars;
    spec.validate();
    return spec;
}

std::string sweep_inputs(const SweepSpec& spec, JsonObject& o) {
    auto axis = [](const Axis& a) {
        return JsonObject().string("name", a.name).number("lo", a.lo).number("hi", a.hi).integer("count", a.count).str();
    };
    o.string("model", spec.model).json("fixed", json_parameters(spec.fixed)).json("x", axis(spec.x)).json("y", axis(spec.y))
        .json("ring", json_ring(spec.cars));
    return o.str();
}

/// The curves of a boundary set: per curve its kind, mode and the points as arrays.
py::list curves_arrays(const BoundarySet& b) {
    py::list curves;
    for (std::size_t i = 0; i < b.curves.size(); ++i) {
        const BoundaryCurve& c = b.curves[i];
        const auto n = static_cast<py::ssize_t>(c.points.size());
        py::array_t<double> x(n), y(n), omega(n);
        auto xm = x.mutable_unchecked<1>();
        auto ym = y.mutable_unchecked<1>();
        auto om = omega.mutable_unchecked<1>();
        for (py::ssize_t k = 0; k < n; ++k) {
            const BoundaryPoint& p = c.points[static_cast<std::size_t>(k)];
            xm(k) = p.x;
            ym(k) = p.y;
            om(k) = p.omega;
        }
        py::dict d;
        d["branch"] = i + 1;
        d["kind"] = kind_name(c.kind);
        d["subkind"] = subkind_name(c.kind);
        d["mode"] = c.kind == BoundaryKind::RingHopf ? py::object(py::int_(c.mode)) : py::object(py::none());
        d["x"] = x;
        d["y"] = y;
        d["omega"] = omega;
        d["closed"] = c.closed;
        d["max_residual"] = c.max_residual;
        curves.append(d);
    }
    return curves;
}

py::tuple py_sweep(const std::string& model, const ParameterMap& fixed, const std::string& x_name, const std::string& x_text,
                const std::string& y_name, const std::string& y_text, int cars, bool boundaries, const std::string& ring_curves_text,
                const std::string& mark, const CarTables& tables, const std::string& prefix, bool peak) {
    SweepSpec spec = sweep_spec(model, fixed, x_name, x_text, y_name, y_text, cars);
    spec.peak = peak;
    // the cars to mark, read and checked before the work (their notes as Python warnings)
    std::vector<std::string> notes;
    const std::vector<ChartMarker> marks =
        mark.empty() ? std::vector<ChartMarker>{} : car_markers(distinct_cars(read_cars(mark, kMaxCars, "", &tables)), spec, &notes);
    for (const auto& n : notes) PyErr_WarnEx(PyExc_UserWarning, ("sweep: mark: " + n).c_str(), 1);
    const RingCurves ring_curves = resolve_ring_curves(parse_ring_curves(ring_curves_text), spec);
    // as the CLI: every mode's curve needs every mode's root; the envelope takes the winding sweep
    if (boundaries && ring_curves == RingCurves::All && spec.cars > 0) spec.ring_method = "modes";
    BoundaryOptions bo;
    bo.ring_curves = ring_curves;
    ExecutionPolicy policy;
    policy.progress = interruptible();
    bo.progress = interruptible();
    BoundarySet b;
    const SweepResult sw = released([&] {
        SweepResult r = run_sweep(spec, policy);
        if (boundaries) b = trace_boundaries(r, bo);
        return r;
    });
    const BoundarySet* bp = boundaries ? &b : nullptr;
    JsonEnvelope e;
    e.command = "sweep";
    JsonObject in;
    sweep_inputs(spec, in);
    in.boolean("boundaries", boundaries).string("ring_curves", ring_curves_name(ring_curves));
    if (peak) in.boolean("peak", true);
    if (!mark.empty()) in.string("mark", mark);
    e.inputs = in.str();
    e.has_solver = true;  // the ring method: winding tables, or per mode where boundaries need it
    e.solver_given = spec.ring_method;
    e.solver_used = sw.ring_method;
    e.status = sw.uncertified > 0 ? "uncertified" : "converged";
    e.message = sweep_message(sw);
    e.result = sweep_json(sw, bp);
    if (!prefix.empty()) {
        // the files of `ddemap sweep --out PREFIX`: grid, envelope, chart (with the marks), boundaries
        std::vector<std::pair<std::string, std::string>> files = {
            {prefix + ".csv", sweep_csv(sw)}, {prefix + ".json", envelope_json(e)}, {prefix + ".svg", sweep_chart_svg(spec, sw, bp, marks)}};
        if (bp) files.emplace_back(prefix + "-boundaries.csv", boundary_csv(spec, b));
        write_files_atomic(files, bp ? std::vector<std::string>{} : std::vector<std::string>{prefix + "-boundaries.csv"});
    }

    // the grid: one (ny, nx) array per quantity (rows: y, columns: x), as the CSV's columns
    const py::ssize_t nx = spec.x.count, ny = spec.y.count;
    auto grid = [&](auto get, auto zero) {
        py::array_t<decltype(zero)> a({ny, nx});
        auto m = a.template mutable_unchecked<2>();
        for (py::ssize_t iy = 0; iy < ny; ++iy)
            for (py::ssize_t ix = 0; ix < nx; ++ix) m(iy, ix) = get(sw.at(static_cast<int>(ix), static_cast<int>(iy)));
        return a;
    };
    py::dict g;
    g["spectral_abscissa"] = grid([](const SweepPoint& p) { return p.spectral_abscissa; }, 0.0);
    g["unstable_roots"] = grid([](const SweepPoint& p) { return p.unstable_roots; }, 0);
    g["sup_gamma"] = grid([](const SweepPoint& p) { return p.sup_gamma; }, 0.0);
    g["omega_peak"] = grid([](const SweepPoint& p) { return p.omega_peak; }, 0.0);
    g["plant_stable"] = grid([](const SweepPoint& p) { return p.plant_stable; }, false);
    g["ring_stable"] = grid([](const SweepPoint& p) { return p.ring_stable; }, false);
    g["string_stable"] = grid([](const SweepPoint& p) { return p.string_stable; }, false);
    if (peak) {  // ||h||_1 (NaN where not computed: L2-unstable points) and the peak verdict
        g["peak_norm"] = grid([](const SweepPoint& p) { return p.peak_norm > 0.0 ? p.peak_norm : std::numeric_limits<double>::quiet_NaN(); }, 0.0);
        g["peak_stable"] = grid([](const SweepPoint& p) { return p.peak_stable; }, false);
    }
    g["abscissa_mode"] = grid([](const SweepPoint& p) { return p.abscissa_mode; }, 0);
    g["plant_abscissa"] = grid([](const SweepPoint& p) { return p.plant_abscissa; }, 0.0);
    g["lowfreq_margin"] = grid([](const SweepPoint& p) { return p.lowfreq_margin; }, 0.0);
    g["peak_gain"] = grid([](const SweepPoint& p) { return p.peak_gain; }, 0.0);
    g["certified"] = grid([](const SweepPoint& p) { return p.certified; }, false);
    // the chart's region: 0 plant unstable, 1 ring unstable, 2 string unstable, 3 string stable
    g["region"] = grid([](const SweepPoint& p) { return region_class(p); }, 0);
    py::array_t<double> xs(nx), ys(ny);
    for (py::ssize_t i = 0; i < nx; ++i) xs.mutable_at(i) = sw.at(static_cast<int>(i), 0).x;
    for (py::ssize_t i = 0; i < ny; ++i) ys.mutable_at(i) = sw.at(0, static_cast<int>(i)).y;
    g["x"] = xs;
    g["y"] = ys;
    return py::make_tuple(envelope_json(e), g, bp ? py::object(curves_arrays(b)) : py::object(py::none()));
}

py::tuple py_boundary(const std::string& model, const ParameterMap& fixed, const std::string& x_name, const std::string& x_text,
                   const std::string& y_name, const std::string& y_text, int cars, int seed_grid, const std::string& ring_curves_text) {
    SweepSpec spec = sweep_spec(model, fixed, x_name, x_text, y_name, y_text, cars);
    const RingCurves ring_curves = resolve_ring_curves(parse_ring_curves(ring_curves_text), spec);
    if (ring_curves == RingCurves::All && spec.cars > 0) spec.ring_method = "modes";  // as the CLI: every mode's root
    BoundaryOptions bo;
    bo.ring_curves = ring_curves;
    ExecutionPolicy policy;
    policy.progress = interruptible();
    bo.progress = interruptible();
    const BoundarySet b = released([&] { return trace_boundaries(run_sweep(spec, policy), bo); });
    JsonEnvelope e;
    e.command = "boundary";
    JsonObject in;
    sweep_inputs(spec, in);
    e.inputs = in.integer("seed_grid", seed_grid).string("ring_curves", ring_curves_name(ring_curves)).str();
    e.message = b.rejected > 0 ? std::to_string(b.rejected) + " seeds failed their Newton correction (the branches through the others were traced)" : "";
    e.result = boundary_json(b);
    return py::make_tuple(envelope_json(e), curves_arrays(b));
}

std::string py_classify(const std::string& spec, const CarTables& tables, int cars, int samples, int ring_samples, unsigned long long seed,
                        bool peak, bool distance) {
    std::vector<CalibratedVehicle> vehicles;
    std::string source = "the paper's calibration table (built in)";
    if (spec.empty()) {
        vehicles = paper_calibration_table();
    } else {
        vehicles = distinct_cars(vehicles_spec(spec, tables));
        source = spec;
    }
    UncertaintyOptions uo;
    uo.samples = samples;
    uo.domain = classification_domain();  // as the CLI
    uo.ring_samples = ring_samples;
    uo.seed = seed;
    ExecutionPolicy policy;
    policy.progress = interruptible();
    StringOptions so;
    so.peak = peak;
    const auto rows = released([&] {
        auto out = classify(vehicles, cars, uo, policy, so);
        if (distance) add_verdict_distances(out, {}, policy);
        return out;
    });
    JsonEnvelope e;
    e.command = "classify";
    JsonObject inputs;
    inputs.string("vehicles", source).json("ring", json_ring(cars));
    if (peak) inputs.boolean("peak", true);
    if (distance) inputs.boolean("distance", true);
    for (const auto& r : rows)
        if (r.has_uncertainty) {
            inputs.integer("samples", uo.samples).integer("ring_samples", uo.ring_samples).integer("seed", static_cast<long long>(uo.seed));
            break;
        }
    e.inputs = inputs.str();
    e.result = classification_json(rows, cars, source);
    e.status = to_string(classification_status(rows));
    e.message = classification_message(rows);
    return envelope_json(e);
}

py::tuple py_simulate(const std::string& fleet, const CarTables& tables, const std::string& lead_profile, const std::string& lead_file,
                      const std::string& lead_text, int lead_car, const std::string& on_event, double t_end, double step, double output_dt,
                      double noise_speed, double noise_gap, unsigned long long seed) {
    SimOptions o;
    o.step = step;
    o.t_end = t_end;
    o.output_dt = output_dt;
    if (on_event == "stop") o.on_event = OnEvent::Stop;
    else if (on_event != "continue") throw std::invalid_argument("on_event = '" + on_event + "': expected stop or continue");
    o.validate();
    std::string label;
    const LeadProfile lead = lead_from(lead_profile, lead_file, lead_text, lead_car, label);
    const std::vector<SimCar> cars = platoon_from(vehicles_spec(fleet, tables));
    o.progress = interruptible();
    SimResult r = released([&] { return simulate_platoon(lead, cars, o); });
    const std::string summary = simulation_json(r, label);  // the exact run; the series carry the noise
    add_measurement_noise(r, noise_speed, noise_gap, seed);
    JsonEnvelope e;
    e.command = "simulate";
    e.inputs = JsonObject()
                   .string("fleet", fleet)
                   .string("lead", label)
                   .string("on_event", on_event)
                   .number("t_end", o.t_end)
                   .number("step", o.step)
                   .number("output_dt", o.output_dt)
                   .number("noise_speed_sd", noise_speed)
                   .number("noise_gap_sd", noise_gap)
                   .integer("seed", static_cast<long long>(seed))
                   .str();
    e.status = to_string(r.status);
    e.message = r.message;
    e.result = summary;
    // the time series: (cars + 1, samples) arrays, row 0 the lead (its gap row NaN)
    const auto n = static_cast<py::ssize_t>(r.time.size()), rows = static_cast<py::ssize_t>(r.speed.size());
    py::array_t<double> time(n), position({rows, n}), speed({rows, n}), gap({rows, n});
    for (py::ssize_t k = 0; k < n; ++k) time.mutable_at(k) = r.time[static_cast<std::size_t>(k)];
    for (py::ssize_t c = 0; c < rows; ++c)
        for (py::ssize_t k = 0; k < n; ++k) {
            const auto ci = static_cast<std::size_t>(c), ki = static_cast<std::size_t>(k);
            position.mutable_at(c, k) = ki < r.position[ci].size() ? r.position[ci][ki] : std::nan("");
            speed.mutable_at(c, k) = ki < r.speed[ci].size() ? r.speed[ci][ki] : std::nan("");
            gap.mutable_at(c, k) = ci < r.gap.size() && ki < r.gap[ci].size() ? r.gap[ci][ki] : std::nan("");
        }
    py::dict series;
    series["time"] = time;
    series["position"] = position;
    series["speed"] = speed;
    series["gap"] = gap;
    return py::make_tuple(envelope_json(e), series);
}

std::string py_calibrate(const std::vector<std::pair<std::string, std::string>>& files, int follower, bool joint, const std::string& car, std::optional<std::pair<double, double>> train,
                      const std::vector<std::tuple<std::string, double, double>>& bounds, double gap_weight, double lead_noise, bool lead_noise_correction,
                      const std::string& runs, const std::string& data_dir, const std::string& report) {
    CalibrationOptions o;
    o.gap_weight = gap_weight;
    o.lead_noise = lead_noise;
    o.lead_noise_correction = lead_noise_correction;
    if (train) {
        o.train_start = train->first;
        o.train_end = train->second;
        if (!(o.train_start >= 0 && o.train_end > o.train_start))
            throw std::invalid_argument("train = (" + json_number(o.train_start) + ", " + json_number(o.train_end) + "): expected 0 <= T0 < T1 [s]");
    }
    for (const auto& [name, lo, hi] : bounds) o.set_bounds(name, lo, hi);
    o.validate();
    if (!runs.empty() && !files.empty()) throw std::invalid_argument("runs = '" + runs + "': give the files in the run list, not also as files");
    if (runs.empty() && files.empty()) throw std::invalid_argument("files: expected at least one trace (or runs=RUNS.csv)");
    if (!data_dir.empty() && runs.empty()) throw std::invalid_argument("data_dir = '" + data_dir + "': only with runs=RUNS.csv");
    if (joint && !runs.empty()) throw std::invalid_argument("joint: not with runs (the run list groups the runs into cars)");
    std::vector<CarRuns> cars;
    auto base_name = [](const std::string& path) {
        std::string b = path.substr(path.find_last_of('/') == std::string::npos ? 0 : path.find_last_of('/') + 1);
        if (b.size() > 4 && b.substr(b.size() - 4) == ".csv") b.resize(b.size() - 4);
        return b;
    };
    if (!runs.empty()) {
        auto read = [&](const std::string& name) {
            const std::string file = data_dir.empty() || name.front() == '/' ? name : (std::filesystem::path(data_dir) / name).string();
            return read_trace_csv(read_text_file(file), file);
        };
        cars = cars_from_run_list(read_run_list_csv(read_text_file(runs), runs), read, "runs " + runs);
    } else {
        // (source, text): a file when the text is empty, else a table in memory named `source`
        bool platoon = false;
        if (joint) cars.push_back(CarRuns{car, {}, {}, {}});
        for (const auto& [source, given] : files) {
            const std::string text = given.empty() ? read_text_file(source) : given;
            const bool is_platoon = is_platoon_csv(text);
            platoon = platoon || is_platoon;
            for (Trace& t : read_traces_csv(text, source, is_platoon ? follower : 0)) {
                const std::string name = is_platoon ? base_name(source) + "-" + t.source.substr(t.source.rfind(':') + 1) : base_name(source);
                if (joint) cars[0].train.push_back(std::move(t));
                else cars.push_back(CarRuns{name, {std::move(t)}, {}, {}});
            }
        }
        if (follower != 0 && !platoon) throw std::invalid_argument("follower = " + std::to_string(follower) + ": none of the traces is a platoon (simulate's CSV)");
    }
    // one counter reaches the progress callback: the fits done of several cars, or the stages of
    // one fit (its design points, then its Levenberg-Marquardt iterations, counted after them);
    // the other checks Ctrl-C only
    const bool one = cars.size() == 1;
    ExecutionPolicy policy;
    policy.progress = interruptible(!one);
    const Progress stage = interruptible(one);
    // (every iteration of every start counted once, so the count never goes back)
    const long points = o.design_points, lm_total = static_cast<long>(o.starts) * o.max_iterations;
    auto lm_done = std::make_shared<std::atomic<long>>(0);
    o.progress = [stage, points, lm_total, lm_done](long done, long total) {  // Ctrl-C within a fit
        if (total == points) stage(done, points + lm_total);
        else stage(points + std::min(++*lm_done, lm_total), points + lm_total);
    };
    const std::vector<CarCalibration> results = released([&] { return calibrate_cars(cars, o, policy); });
    std::vector<CalibrationResult> fits;
    std::vector<std::string> names;
    for (const auto& r : results) {
        fits.push_back(r.fit);
        names.push_back(r.car);
    }
    JsonEnvelope e;
    e.command = "calibrate";
    std::vector<std::string> traces;
    for (const auto& c : cars)
        for (const auto& t : c.train) traces.push_back(json_string(t.source));
    JsonObject in;
    in.json("traces", json_array(traces)).string("model", "ovrv").number("gap_weight", o.gap_weight);
    if (o.lead_noise >= 0.0) in.number("lead_noise", o.lead_noise);
    if (!o.lead_noise_correction) in.boolean("lead_noise_correction", false);
    if (!runs.empty()) in.string("runs", runs);
    if (joint) in.string("joint", car);
    if (o.train_start >= 0) in.json("train", json_array({json_number(o.train_start), json_number(o.train_end)}));
    e.inputs = in.str();
    e.result = calibration_json(names, fits, o, &results);
    Status status = Status::Converged;
    for (std::size_t i = 0; i < fits.size(); ++i)
        if (fits[i].status_code != Status::Converged) {
            if (status == Status::Converged) status = fits[i].status_code;  // the first, as the message
        }
    e.status = to_string(status);
    e.message = calibration_message(names, fits);
    if (!report.empty()) {  // the folder exists (the Python wrapper creates it)
        std::vector<std::pair<std::string, std::string>> out = calibration_report_files(results, cars, o, runs.empty() && !joint);
        for (auto& f : out) f.first = report + "/" + f.first;
        write_files_atomic(out);
    }
    return envelope_json(e);
}

std::string py_mixed_ring(const std::string& spec, const CarTables& tables, bool is_pattern, int cars, std::optional<double> speed,
                          std::optional<double> length, const std::string& solver, int count, int degree) {
    Fleet unit = fleet_spec(spec, tables);
    Fleet fleet;
    if (cars <= 0) fleet = unit;
    else
        for (int i = 0; i < cars; ++i) fleet.push_back(unit[static_cast<std::size_t>(i) % unit.size()]);
    MixedRingOptions o;
    if (speed && length) throw std::invalid_argument("speed and length: expected only one of them");
    if (length) o.length = *length;
    else o.speed = speed ? *speed : 20.0;
    o.roots.method = root_method(solver);
    o.roots.count = count;
    o.roots.degree = degree;
    o.roots.progress = branch_interruptible();
    const MixedRingResult r = released([&] { return analyse_mixed_ring(fleet, o); });
    if (r.roots.status == Status::Cancelled) throw Interrupted();  // Ctrl-C: KeyboardInterrupt
    const RootResult& rr = r.roots;
    JsonEnvelope e;
    e.command = "roots";
    JsonObject in;
    in.string(is_pattern ? "fleet_pattern" : "fleet", spec).integer("ring", static_cast<long long>(fleet.size()));
    if (std::isnan(o.length)) in.number("speed", o.speed);
    else in.number("length", o.length);
    in.integer("count", o.roots.count).integer("degree", o.roots.degree);
    e.inputs = in.str();
    e.has_solver = true;
    e.solver_given = solver_name(rr.method_given);
    e.solver_used = solver_name(rr.method_used);
    e.status = to_string(rr.status);
    e.message = rr.message;
    e.result = mixed_ring_json(r, fleet.size());
    return envelope_json(e);
}

/// One car of a car list (mix --x, --y): the list must name exactly one distinct car.
FleetCar one_car(const std::string& what, const std::string& spec, const CarTables& tables) {
    const std::vector<CalibratedVehicle> cars = distinct_cars(read_cars(spec, kMaxCars, "", &tables));
    if (cars.size() != 1) {
        std::string names;
        for (const auto& c : cars) names += (names.empty() ? "" : ", ") + c.name;
        throw std::invalid_argument(what + " = '" + spec + "': " + std::to_string(cars.size()) + " different cars (" + names + "): expected one car");
    }
    return to_fleet(cars).front();
}

std::string py_mix(const std::string& x_spec, const std::string& y_spec, const CarTables& tables, int cars, const std::vector<double>& fractions,
                   int draws, unsigned seed, std::optional<double> speed, std::optional<double> length, const std::string& solver) {
    const FleetCar x = one_car("x", x_spec, tables), y = one_car("y", y_spec, tables);
    MixOptions o;
    o.cars = cars;
    o.fractions = fractions;
    o.draws = draws;
    o.seed = seed;
    if (speed && length) throw std::invalid_argument("speed and length: expected only one of them");
    if (length) o.ring.length = *length;
    else o.ring.speed = speed ? *speed : 20.0;
    o.ring.roots.method = root_method(solver);
    o.ring.roots.count = 4;
    o.validate();
    o.progress = branch_interruptible();
    o.ring.roots.progress = branch_interruptible();
    const std::vector<MixPoint> pts = released([&] { return penetration_study(x, y, o); });
    Status status = Status::Converged;
    std::string used;
    for (const auto& pt : pts) {
        if (pt.status == Status::Cancelled) throw Interrupted();
        if (pt.status != Status::Converged) status = pt.status;
        const std::string u = solver_name(pt.method_used);
        if (used.find(u) == std::string::npos) used += (used.empty() ? "" : ",") + u;
    }
    JsonEnvelope e;
    e.command = "mix";
    JsonObject in;
    std::vector<std::string> ps;
    for (double f : o.fractions) ps.push_back(json_number(f));
    in.string("x", x_spec).string("y", y_spec).integer("ring", o.cars).json("p", json_array(ps)).integer("draws", o.draws).integer("seed", o.seed);
    if (std::isnan(o.ring.length)) in.number("speed", o.ring.speed);
    else in.number("length", o.ring.length);
    e.inputs = in.str();
    e.has_solver = true;
    e.solver_given = solver_name(o.ring.roots.method);
    e.solver_used = used;
    e.status = to_string(status);
    e.message = mix_message(pts);
    e.result = mix_json(pts, o.cars);
    return envelope_json(e);
}

std::string py_growth(const std::string& spec, const CarTables& tables, int followers, const std::string& lead_profile, const std::string& lead_file,
                      const std::string& lead_text, int lead_car) {
    std::string label;
    const LeadProfile lead = lead_from(lead_profile, lead_file, lead_text, lead_car, label);
    const std::vector<CalibratedVehicle> vehicles = spec.empty() ? paper_calibration_table() : distinct_cars(vehicles_spec(spec, tables));
    const std::string source = spec.empty() ? "the paper's calibration table (built in)" : spec;
    ExecutionPolicy policy;
    policy.progress = interruptible();
    const auto g = released([&] { return disturbance_growth(vehicles, lead, followers, SimOptions{}, policy); });
    JsonEnvelope e;
    e.command = "growth";
    e.inputs = JsonObject().string("vehicles", source).string("lead", label).integer("followers", followers).str();
    for (const GrowthResult& r : g)
        if (r.status != Status::Converged && e.status == "converged") e.status = to_string(r.status);
    e.message = growth_message(g);
    e.result = growth_json(g, label);
    return envelope_json(e);
}

/// design: the gains of one car that minimise an objective (analysis/design/design.hpp).
std::string py_design(const std::string& spec, const CarTables& tables, const std::string& objective, const std::vector<std::string>& free,
                      const std::vector<std::tuple<std::string, double, double>>& bounds, double margin, const std::vector<double>& weights, int starts,
                      std::optional<double> speed, std::optional<int> cars, bool robust) {
    const std::vector<CalibratedVehicle> found = distinct_cars(vehicles_spec(spec, tables));
    if (found.size() != 1)
        throw std::invalid_argument("car = '" + spec + "': " + std::to_string(found.size()) + " cars: expected one car (e.g. \"mycars.csv:Sedan\")");
    const CalibratedVehicle& car = found.front();
    ParameterMap p = car.parameters;
    if (speed) p["speed"] = *speed;
    DesignOptions o;
    o.objective = parse_design_objective(objective);
    o.free = free;
    for (const auto& [name, lo, hi] : bounds) o.bounds.push_back({name, lo, hi});
    o.margin = margin;
    o.weights = weights;
    o.starts = starts;
    o.cars = cars ? *cars : -1;
    if (car.has_covariance && car.model == "ovrv") {  // a fit: judged under its uncertainty too, as the command does
        o.has_covariance = true;
        o.covariance = car.covariance;
    }
    if (robust && !o.has_covariance)
        throw std::invalid_argument("robust: the car " + car.name + " has no covariance: expected a fit of calibrate (its Result, JSON or CSV with cov_ columns)");
    o.robust = robust;
    o.progress = interruptible();
    const DesignResult r = released([&] { return design_gains(car.model, p, o); });
    const JsonEnvelope e = design_envelope(r, o, spec, car.name);
    return envelope_json(e);
}

/// chart: a chart spec (TOML text; `source` names it and its folder holds the files it names)
/// rendered to PREFIX.svg and the panels' CSVs.
std::string py_chart(const std::string& text, const std::string& source, const std::string& prefix) {
    const ChartSpec spec = parse_chart_spec(text, source);
    ExecutionPolicy policy;
    policy.progress = interruptible();
    const RenderedChart r = released([&] { return render_chart(spec, policy); });
    const auto files = chart_files(r, prefix);
    write_files_atomic(files);
    std::vector<std::string> names;
    for (const auto& f : files) names.push_back(json_string(f.first));
    JsonEnvelope e;
    e.command = "chart";
    e.inputs = JsonObject().string("spec", source).string("out", prefix).str();
    e.result = JsonObject().integer("panels", static_cast<long long>(spec.panels.size())).number("seconds", r.seconds).json("files", json_array(names)).str();
    return envelope_json(e);
}

/// atlas: an atlas spec (TOML text) computed in this process (the chunks in parallel; no MPI,
/// no chunk store), sized first as `ddemap atlas` sizes it (refused above 600 s of computing or
/// 2 GB of values unless `allow_large`). Returns (envelope, fields, coordinates): every stored
/// quantity as an array of the grid's shape (rings x axes, C order), the ring sizes (0 = inf) and
/// each axis's values; with a prefix also PREFIX.h5 and PREFIX.svg, as the command writes them.
py::tuple py_atlas(const std::string& text, const std::string& source, const std::string& prefix, bool allow_large) {
    const auto t0 = std::chrono::steady_clock::now();
    const AtlasFile file = parse_atlas_spec(text, source);
    const AtlasSpec& spec = file.spec;
    const std::vector<AtlasField>& fields = atlas_fields();
    const std::size_t nf = fields.size();
    {
        // the command's estimate: 5e-5 s per ring mode and point (12 modes on the winding path)
        const bool winding = spec.ring_method_used() == "winding";
        double modes = 0.0;
        for (int n : spec.rings) modes += n == 0 || winding ? 12.0 : n / 2 + 1.0;
        const int threads = std::max(1u, std::thread::hardware_concurrency());
        const double seconds = static_cast<double>(spec.points()) / static_cast<double>(spec.rings.size()) * modes * 5e-5 / threads;
        const double bytes = static_cast<double>(spec.points()) * static_cast<double>(nf) * 8.0 * 2.0;
        if (!allow_large && (seconds > 600.0 || bytes > 2e9))
            throw std::invalid_argument("an atlas of " + std::to_string(spec.points()) + " points: about " + json_number(std::round(seconds)) + " s and " +
                                        json_number(std::round(bytes / 1e6)) +
                                        " MB of values: above the limit of 600 s or 2000 MB (allow_large=True runs it; the command ddemap atlas "
                                        "keeps only a chunk in memory and resumes)");
    }
    std::vector<double> values(static_cast<std::size_t>(spec.points()) * nf);
    ExecutionPolicy policy;
    policy.progress = interruptible();
    released([&] {
        parallel_for(spec.chunks(), [&](long c) {
            const std::vector<double> v = evaluate_atlas_chunk(spec, c);
            std::copy(v.begin(), v.end(), values.begin() + static_cast<std::ptrdiff_t>(static_cast<std::size_t>(spec.chunk_begin(c)) * nf));
        }, policy);
        return 0;
    });
    std::vector<std::string> files;
    if (!prefix.empty()) {
        write_files_atomic({{prefix + ".h5", atlas_hdf5(spec, values, text)}, {prefix + ".svg", atlas_svg(file, values)}});
        files = {json_string(prefix + ".h5"), json_string(prefix + ".svg")};
    }
    // the verdict classes and the points without a certificate, as the command counts them
    std::size_t f_class = nf, f_certified = nf;
    for (std::size_t f = 0; f < nf; ++f) {
        if (std::string(fields[f].name) == "region") f_class = f;
        if (std::string(fields[f].name) == "certified") f_certified = f;
    }
    long classes[4] = {0, 0, 0, 0}, uncertified = 0;
    for (long i = 0; i < spec.points(); ++i) {
        const double* v = values.data() + static_cast<std::size_t>(i) * nf;
        if (f_class < nf) ++classes[std::clamp(static_cast<int>(v[f_class]), 0, 3)];
        if (f_certified < nf) uncertified += v[f_certified] == 0.0;
    }
    const std::vector<long> shape = spec.shape();
    std::vector<py::ssize_t> dims(shape.begin(), shape.end());
    py::dict out_fields, coords;
    for (std::size_t f = 0; f < nf; ++f) {
        py::array_t<double> a(dims);
        double* d = a.mutable_data();
        for (long i = 0; i < spec.points(); ++i) d[i] = values[static_cast<std::size_t>(i) * nf + f];
        out_fields[fields[f].name] = a;
    }
    coords["ring"] = py::array_t<int>(static_cast<py::ssize_t>(spec.rings.size()), spec.rings.data());
    std::vector<std::string> axis_names;
    for (const AtlasAxis& ax : spec.axes) {
        coords[ax.name.c_str()] = py::array_t<double>(static_cast<py::ssize_t>(ax.values.size()), ax.values.data());
        axis_names.push_back(json_string(ax.name));
    }
    std::vector<std::string> shape_json;
    for (long n : shape) shape_json.push_back(std::to_string(n));
    JsonEnvelope e;
    e.command = "atlas";
    e.inputs = JsonObject().string("spec", source).string("out", prefix).str();
    e.has_solver = true;
    e.solver_given = spec.ring_method;
    e.solver_used = spec.ring_method_used();
    e.status = uncertified > 0 ? "uncertified" : "converged";
    e.message = uncertified > 0 ? std::to_string(uncertified) + (uncertified == 1 ? " point has" : " points have") +
                                      " no certificate even after collocation (see the 'certified' field)"
                                : "every one of the " + std::to_string(spec.points()) +
                                      " points certified: no root of the plant or of the ring lies right of the abscissa reported (argument principle)";
    e.result = JsonObject()
                   .integer("points", spec.points())
                   .json("shape", json_array(shape_json))
                   .json("axes", json_array(axis_names))
                   .integer("chunks", spec.chunks())
                   .json("regions", JsonObject()
                                        .integer("plant_unstable", classes[0])
                                        .integer("ring_unstable", classes[1])
                                        .integer("string_unstable", classes[2])
                                        .integer("string_stable", classes[3])
                                        .str())
                   .integer("uncertified", uncertified)
                   .number("seconds", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count())
                   .json("files", json_array(files))
                   .str();
    return py::make_tuple(envelope_json(e), out_fields, coords);
}

/// paper: the seed paper's job under PREFIX, as `ddemap paper --out PREFIX`.
std::string py_paper(const std::string& prefix) {
    const Progress check = interruptible();
    const PaperJob job = released([&] {
        return run_paper_job(ddemap::cli::builtin_paper_toml, "maps/paper.toml", ddemap::cli::builtin_classification_toml, "maps/classification.toml",
                             {}, check);
    });
    return write_paper(job, prefix);
}

/// The problem of the nonlinear commands (equilibria, hopf, orbits), as their flag group builds it:
/// a system file, or a built-in ring by name (traffic/nonlinear_ring.hpp) with `par` set to `from`.
struct NonlinearProblem {
    std::unique_ptr<NonlinearDDE> system;
    std::vector<std::string> variables;
    std::map<std::string, std::string> units;
    Eigen::VectorXd guess;
    JsonObject inputs;
};

NonlinearProblem nonlinear_problem(const std::string& system_file, const std::string& model, int ring, const ParameterMap& parameters,
                                   const std::string& par, double from, double to) {
    if (from == to) throw std::invalid_argument("to = " + json_number(to) + ": expected a value other than from");
    NonlinearProblem r;
    if (!system_file.empty()) {
        NonlinearSystemFile file = read_nonlinear_system_json(read_text_file(system_file), system_file);
        r.variables = file.system->variables();
        r.guess = file.equilibrium;
        r.system = std::make_unique<ExpressionSystem>(*file.system);
        r.inputs.string("system", system_file);
    } else {
        NonlinearRing built = make_nonlinear_ring(model, ring, parameters, par, from);
        r.variables = built.variables;
        r.units = built.units;
        r.guess = built.uniform_flow;
        r.system = std::move(built.system);
        r.inputs.string("model", model).integer("ring", ring);
    }
    add_held_parameters(r.inputs, *r.system, par);  // an unknown par: ValueError naming the known ones
    return r;
}

/// The second parameter of a two-parameter curve (hopf, equilibria with par2): its box checked
/// as the command line checks it, in the Python arguments' names; the branch options copied in.
void second_parameter(NonlinearProblem& pb, const EquilibriumBranchOptions& o, const std::string& par2, std::optional<double> from2,
                      std::optional<double> to2, TwoParameterOptions& co) {
    if (!from2 || !to2) throw std::invalid_argument("par2 needs from2 and to2: expected the box of " + par2);
    if (par2 == o.parameter) throw std::invalid_argument("par2 = '" + par2 + "': expected a parameter other than par");
    const int j2 = pb.system->parameter_index(par2);
    co.branch = o;
    co.parameter2 = par2;
    co.from2 = *from2;
    co.to2 = *to2;
    if (!(co.from2 < co.to2)) throw std::invalid_argument("from2 = " + json_number(co.from2) + ", to2 = " + json_number(co.to2) + ": expected from2 < to2");
    const double held = pb.system->parameter_values()[static_cast<std::size_t>(j2)];
    if (!(held >= co.from2 && held <= co.to2))
        throw std::invalid_argument("par2 " + par2 + " = " + json_number(held) + " (its value in the system): expected it in [from2, to2]");
    co.continuation.max_points = o.continuation.max_points;
    pb.inputs.string("par2", par2).number("from2", co.from2).number("to2", co.to2);
}

std::string py_equilibria(const std::string& system_file, const std::string& model, int ring, const ParameterMap& parameters,
                          const std::string& par, double from, double to, int count, int max_points, const std::string& par2,
                          std::optional<double> from2, std::optional<double> to2, std::optional<int> branch_point) {
    NonlinearProblem pb = nonlinear_problem(system_file, model, ring, parameters, par, from, to);
    EquilibriumBranchOptions o;
    o.parameter = par;
    o.from = from;
    o.to = to;
    o.roots.count = count;
    o.continuation.max_points = max_points;
    pb.inputs.string("par", par).number("from", o.from).number("to", o.to).integer("count", o.roots.count);
    const bool two = !par2.empty();
    if (!two && (from2 || to2)) throw std::invalid_argument("from2/to2 without par2: expected par2=NAME with them");
    if (two && branch_point) throw std::invalid_argument("branch_point: not with par2 (expected one branch in par)");
    JsonEnvelope e;
    e.command = "equilibria";
    e.has_solver = true;  // as the CLI: the root method (its names there: shift_invert = sparse, contour = product)
    e.solver_given = o.roots.method == "shift_invert" ? "sparse" : o.roots.method == "contour" ? "product" : o.roots.method;
    e.solver_used = e.solver_given;
    if (two) {  // the fold curves through the branch's folds, as `equilibria --par2`
        FoldCurveOptions co;
        second_parameter(pb, o, par2, from2, to2, co);
        co.branch.progress = branch_interruptible();
        co.progress = branch_interruptible();
        const FoldCurves c = released([&] { return fold_curves(*pb.system, pb.guess, co); });
        e.inputs = pb.inputs.str();
        e.status = to_string(c.status);
        e.message = c.message;
        e.result = fold_curves_json(c, par2, pb.variables);
        return envelope_json(e);
    }
    o.progress = branch_interruptible();
    EquilibriumBranch b = released([&] { return equilibrium_branch(*pb.system, pb.guess, o); });
    // the other branch through branch point K (as equilibria --branch-point)
    std::string switched;
    if (branch_point) {
        const int k = *branch_point;
        std::vector<const FoldPoint*> points;
        for (const FoldPoint& f : b.folds)
            if (f.kind == "branch_point") points.push_back(&f);
        if (points.empty())
            throw std::invalid_argument("branch_point = " + std::to_string(k) + ": the branch has no branch point in " + par + " from " + json_number(from) +
                                        " to " + json_number(to) + " (expected at least one to switch at)");
        if (k >= static_cast<int>(points.size()))
            throw std::invalid_argument("branch_point = " + std::to_string(k) + ": expected an index from 0 to " + std::to_string(points.size() - 1));
        const FoldPoint& bp = *points[static_cast<std::size_t>(k)];
        pb.inputs.integer("branch_point", k);
        EquilibriumBranch nb;
        if (bp.status != Status::Converged) {
            nb.status = bp.status;
            nb.message = "branch point " + std::to_string(k) + " was not located: no branch switched onto";
        } else {
            nb = released([&] { return equilibrium_branch_from_branch_point(*pb.system, b, bp, o, BranchSide::Both); });
        }
        if (nb.status != Status::Converged && b.status == Status::Converged) {
            b.status = nb.status;
            b.message = "the other branch at the branch point: " + nb.message;
        }
        JsonObject from_j;
        from_j.integer("index", k).number("par", bp.par);
        switched = ",\"switched\":{\"from\":" + from_j.str() + "," + equilibrium_branch_json(nb, pb.variables).substr(1);
    }
    e.inputs = pb.inputs.str();
    e.status = to_string(b.status);
    e.message = b.message;
    e.result = equilibrium_branch_json(b, pb.variables);
    if (!switched.empty()) e.result = e.result.substr(0, e.result.size() - 1) + switched + "}";
    return envelope_json(e);
}

std::string py_hopf(const std::string& system_file, const std::string& model, int ring, const ParameterMap& parameters, const std::string& par,
                    double from, double to, const std::string& par2, std::optional<double> from2, std::optional<double> to2, int max_points) {
    NonlinearProblem pb = nonlinear_problem(system_file, model, ring, parameters, par, from, to);
    if (!(from < to)) throw std::invalid_argument("from = " + json_number(from) + ", to = " + json_number(to) + ": expected from < to");
    const bool two = !par2.empty();
    if (!two && (from2 || to2)) throw std::invalid_argument("from2/to2 without par2: expected par2=NAME with them");
    EquilibriumBranchOptions o;
    o.parameter = par;
    o.from = from;
    o.to = to;
    o.continuation.max_points = max_points;
    pb.inputs.string("par", par).number("from", o.from).number("to", o.to);
    HopfCurveOptions co;
    if (two) second_parameter(pb, o, par2, from2, to2, co);
    JsonEnvelope e;
    e.command = "hopf";
    e.inputs = pb.inputs.str();
    e.has_solver = true;  // as the CLI (equilibria)
    e.solver_given = o.roots.method == "shift_invert" ? "sparse" : o.roots.method == "contour" ? "product" : o.roots.method;
    e.solver_used = e.solver_given;
    if (two) {
        co.branch.progress = branch_interruptible();
        co.progress = branch_interruptible();
        const HopfCurves c = released([&] { return hopf_curves(*pb.system, pb.guess, co); });
        e.status = to_string(c.status);
        e.message = c.message;
        e.result = hopf_curves_json(c, par2, pb.variables);
    } else {
        o.progress = branch_interruptible();
        const HopfAnalysis h = released([&] { return hopf_points(*pb.system, pb.guess, o); });
        e.status = to_string(h.status);
        e.message = h.message;
        e.result = hopf_points_json(h, pb.variables);
    }
    return envelope_json(e);
}

std::string py_bistability(const std::string& system_file, const std::string& model, int ring, const ParameterMap& parameters, const std::string& par,
                           double from, double to, const std::string& par2, double from2, double to2, int degree, int intervals, int points, int rows) {
    NonlinearProblem pb = nonlinear_problem(system_file, model, ring, parameters, par, from, to);
    if (!(from < to)) throw std::invalid_argument("from = " + json_number(from) + ", to = " + json_number(to) + ": expected from < to");
    if (par2 == par) throw std::invalid_argument("par2 = '" + par2 + "': expected a parameter other than par");
    const int j2 = pb.system->parameter_index(par2);
    if (!(from2 < to2)) throw std::invalid_argument("from2 = " + json_number(from2) + ", to2 = " + json_number(to2) + ": expected from2 < to2");
    const double held = pb.system->parameter_values()[static_cast<std::size_t>(j2)];
    if (!(held >= from2 && held <= to2))
        throw std::invalid_argument("par2 " + par2 + " = " + json_number(held) + " (its value in the system): expected it in [from2, to2]");
    BistabilityOptions o;
    o.parameter = par;
    o.from = from;
    o.to = to;
    o.parameter2 = par2;
    o.from2 = from2;
    o.to2 = to2;
    o.degree = degree;
    o.intervals = intervals;
    o.max_points = points;
    o.rows = rows;
    pb.inputs.string("par", o.parameter).number("from", o.from).number("to", o.to).string("par2", o.parameter2).number("from2", o.from2).number("to2", o.to2)
        .integer("degree", o.degree).integer("intervals", o.intervals).integer("points", o.max_points).integer("rows", o.rows);
    o.progress = branch_interruptible();
    const BistabilityChart chart = released([&] { return bistability_chart(*pb.system, pb.guess, o); });
    JsonEnvelope e;
    e.command = "bistability";
    e.inputs = pb.inputs.str();
    e.status = to_string(chart.status);
    e.message = chart.message;
    e.result = bistability_json(chart, pb.variables);
    return envelope_json(e);
}

std::string py_orbits(const std::string& system_file, const std::string& model, int ring, const ParameterMap& parameters, const std::string& par,
                      double from, double to, int hopf, int degree, int intervals, int points, bool adapt, std::optional<double> max_step,
                      std::optional<int> period_doubling, std::optional<double> from_simulation, std::optional<std::vector<double>> history,
                      std::optional<std::vector<double>> guess_times, std::optional<std::vector<std::vector<double>>> guess_states,
                      const std::string& guess_label, const std::string& par2, std::optional<double> from2, std::optional<double> to2) {
    const bool two = !par2.empty();
    if (!two && (from2 || to2)) throw std::invalid_argument("from2/to2 without par2: expected par2=NAME with them");
    if (two && (!from2 || !to2)) throw std::invalid_argument("par2 needs from2 and to2: expected the box of " + par2);
    if (two && par2 == par) throw std::invalid_argument("par2 = '" + par2 + "': expected a parameter other than par");
    if (two && !(*from2 < *to2)) throw std::invalid_argument("from2 = " + json_number(*from2) + ", to2 = " + json_number(*to2) + ": expected from2 < to2");
    if (two && adapt) throw std::invalid_argument("par2: not with adapt (the curves are computed on the uniform mesh)");
    const bool from_sim = from_simulation.has_value(), from_data = guess_times.has_value();
    if (from_sim && from_data) throw std::invalid_argument("from_simulation and guess: expected one start of the orbits");
    if (history && !from_sim) throw std::invalid_argument("history: only with from_simulation (expected from_simulation=T_END)");
    if (from_sim && !(*from_simulation > 0.0 && *from_simulation <= 1e7))
        throw std::invalid_argument("from_simulation = " + json_number(*from_simulation) + ": expected a run time above 0, at most 1e7");
    PeriodicOrbitOptions o;
    if (max_step) {  // as orbits --max-step, checked before any work
        if (!(*max_step >= o.initial_step && *max_step <= 1e6))
            throw std::invalid_argument("max_step = " + json_number(*max_step) + ": expected a value from " + json_number(o.initial_step) +
                                        " (the first step) to 1e6");
        o.max_step = *max_step;
    }
    NonlinearProblem pb = nonlinear_problem(system_file, model, ring, parameters, par, from, to);
    o.parameter = par;
    o.from = from;
    o.to = to;
    o.degree = degree;
    o.intervals = intervals;
    o.max_points = points;
    o.adapt = adapt;
    pb.inputs.string("par", par).number("from", o.from).number("to", o.to);
    if (!from_sim && !from_data) pb.inputs.integer("hopf", hopf);
    pb.inputs.integer("degree", o.degree).integer("intervals", o.intervals).integer("points", o.max_points).boolean("adapt", o.adapt);
    if (max_step) pb.inputs.number("max_step", o.max_step);  // only when given, as the command's envelope
    // the starts other than a Hopf point (as orbits --from-simulation, --guess): at par = from
    Eigen::VectorXd sim_history;
    double sim_step = 0.0;
    if (from_sim || from_data) {
        pb.system->set_parameter(par, from);
        pb.inputs.number(from_sim ? "from_simulation" : "guess_at", from);
    }
    if (from_sim) {
        const int n = pb.system->dimension();
        if (history) {
            if (static_cast<int>(history->size()) != n)
                throw std::invalid_argument("history: expected " + std::to_string(n) + " values (one per variable), found " + std::to_string(history->size()));
            sim_history = Eigen::Map<const Eigen::VectorXd>(history->data(), n);
            if (!sim_history.allFinite()) throw std::invalid_argument("history: expected finite values");
        } else {
            sim_history = pb.guess;
            sim_history(0) += 0.1 * std::max(1.0, std::abs(sim_history(0)));
        }
        sim_step = default_simulation_step(*pb.system);
        pb.inputs.number("t_end", *from_simulation);
        if (history) {
            std::string list;
            for (double v : *history) list += (list.empty() ? "" : ",") + format_exact(v);
            pb.inputs.json("history", "[" + list + "]");
        }
    }
    if (from_data) pb.inputs.string("guess", guess_label);
    if (period_doubling) pb.inputs.integer("period_doubling", *period_doubling);
    EquilibriumBranchOptions eo;
    eo.parameter = par;
    eo.from = o.from;
    eo.to = o.to;
    eo.roots.count = 2;
    eo.progress = branch_interruptible();
    o.progress = branch_interruptible();
    const bool from_hopf = !from_sim && !from_data;
    EquilibriumBranch eq;
    if (from_hopf) eq = released([&] { return equilibrium_branch(*pb.system, pb.guess, eo); });
    if (from_hopf && eq.hopf.empty())
        throw std::invalid_argument("no Hopf point on the equilibrium branch in " + par + " from " + json_number(from) + " to " + json_number(to) +
                                    " (ended: " + to_string(eq.stop) + "): expected at least one to start the periodic orbits from");
    if (from_hopf && hopf >= static_cast<int>(eq.hopf.size()))
        throw std::invalid_argument("hopf = " + std::to_string(hopf) + ": expected an index from 0 to " + std::to_string(eq.hopf.size() - 1));
    const HopfPoint* hp = from_hopf ? &eq.hopf[static_cast<std::size_t>(hopf)] : nullptr;
    OrbitBranch b;
    std::string start_json;
    if (hp) {
        b = released([&] { return orbit_branch_from_hopf(*pb.system, *hp, o); });
        if (hp->status != Status::Converged && b.status == Status::Converged) {
            b.status = hp->status;
            b.message = "the Hopf point was not located (" + to_string(hp->status) + "); the orbits start from its estimate";
        }
    } else {
        const PeriodicMesh mesh(o.degree, o.intervals);
        OrbitGuess guess;
        bool have = true;
        if (from_sim) {
            const SimulatedOrbitGuess sg = released([&] { return orbit_guess_from_simulation(*pb.system, par, mesh, sim_history, *from_simulation, sim_step); });
            start_json = simulation_start_json(sg, *from_simulation, sim_step);
            b = released([&] { return orbit_branch_from_simulation(*pb.system, sg, o); });
            have = false;  // done
        } else {
            const std::vector<double>& t = *guess_times;
            const std::vector<std::vector<double>>& x = *guess_states;
            const int n = pb.system->dimension();
            if (x.size() != t.size()) throw std::invalid_argument("guess: expected one state per time");
            Eigen::MatrixXd states(static_cast<Eigen::Index>(t.size()), n);
            for (std::size_t i = 0; i < t.size(); ++i) {
                if (static_cast<int>(x[i].size()) != n)
                    throw std::invalid_argument("guess: row " + std::to_string(i) + ": expected " + std::to_string(n) + " values (one per variable)");
                for (int k = 0; k < n; ++k) states(static_cast<Eigen::Index>(i), k) = x[i][static_cast<std::size_t>(k)];
            }
            if (!states.allFinite()) throw std::invalid_argument("guess: expected finite values");
            if (t.size() < 4) throw std::invalid_argument("guess: expected at least 4 rows covering one period");
            guess = orbit_guess_from_samples(mesh, t, states, t.back() - t.front(), from);
            JsonObject start;
            start.string("kind", "file").string("file", guess_label).number("period", guess.period);
            start_json = start.str();
        }
        if (have) b = released([&] { return orbit_branch_from_guess(*pb.system, guess, o); });
    }
    // the branch of twice the period (as orbits --period-doubling)
    OrbitBranch doubled;
    if (period_doubling) {
        const int k = *period_doubling;
        if (b.period_doublings.empty())
            throw std::invalid_argument("period_doubling = " + std::to_string(k) + ": the branch has no period doubling in " + par + " from " +
                                        json_number(from) + " to " + json_number(to) + " (expected at least one to switch at)");
        if (k >= static_cast<int>(b.period_doublings.size()))
            throw std::invalid_argument("period_doubling = " + std::to_string(k) + ": expected an index from 0 to " + std::to_string(b.period_doublings.size() - 1));
        const OrbitCrossing& pd = b.period_doublings[static_cast<std::size_t>(k)];
        if (!pd.located) {
            doubled.status = Status::NumericalIssue;
            doubled.stop = "first_orbit_failed";
            doubled.message = "period doubling " + std::to_string(k) + " was not located: no branch switched onto";
        } else {
            doubled = released([&] { return orbit_branch_from_period_doubling(*pb.system, pd, o); });
        }
        if (doubled.status != Status::Converged && b.status == Status::Converged) {
            b.status = doubled.status;
            b.message = "the branch of twice the period: " + doubled.message;
        }
    }
    // the curves of folds and of period doublings in (par, par2) (as orbits --par2)
    OrbitBranchCurves bc;
    if (two) {
        const double held = pb.system->parameter_values()[static_cast<std::size_t>(pb.system->parameter_index(par2))];
        if (!(held >= *from2 && held <= *to2))
            throw std::invalid_argument("par2 " + par2 + " = " + json_number(held) + " (its value in the system): expected it in [from2, to2]");
        pb.inputs.string("par2", par2).number("from2", *from2).number("to2", *to2);
        OrbitFoldCurveOptions fo;
        fo.orbit = o;
        fo.parameter2 = par2;
        fo.from2 = *from2;
        fo.to2 = *to2;
        fo.orbit.progress = branch_interruptible();
        bc = released([&] { return orbit_curves_of_branch(*pb.system, b, fo); });
        if (bc.status != Status::Converged && b.status == Status::Converged) {
            b.status = bc.status;
            b.message = bc.message;
        }
    }
    JsonEnvelope e;
    e.command = "orbits";
    e.inputs = pb.inputs.str();
    e.status = to_string(b.status);
    e.message = b.message;
    const std::string result = orbit_branch_json(b, pb.variables);
    if (hp) {
        JsonObject hj;
        hj.integer("index", hopf).number("par", hp->par).number("omega", hp->omega).string("status", to_string(hp->status));
        e.result = "{\"hopf\":" + hj.str() + "," + result.substr(1);
    } else {
        e.result = "{\"start\":" + start_json + "," + result.substr(1);
    }
    if (two)
        e.result = e.result.substr(0, e.result.size() - 1) + ",\"fold_curves\":" + orbit_fold_curves_json(bc.folds, pb.variables) +
                   ",\"period_doubling_curves\":" + orbit_fold_curves_json(bc.period_doublings, pb.variables) +
                   ",\"torus_curves\":" + orbit_fold_curves_json(bc.tori, pb.variables) + "}";
    if (period_doubling) {
        const OrbitCrossing& pd = b.period_doublings[static_cast<std::size_t>(*period_doubling)];
        JsonObject from_j;
        from_j.integer("index", *period_doubling).number("par", pd.par).number("period", pd.period);
        const std::string branch = orbit_branch_json(doubled, pb.variables);
        e.result = e.result.substr(0, e.result.size() - 1) + ",\"period_doubled\":{\"from\":" + from_j.str() + "," + branch.substr(1) + "}";
    }
    return envelope_json(e);
}

}  // namespace

PYBIND11_MODULE(_ddemap, m) {
    g_main_thread = std::this_thread::get_id();
    m.doc() = "ddemap's compiled core: each function returns the JSON envelope of the matching command (use the "
              "wrappers of the ddemap package, which take keyword arguments and return Python objects).";
    m.attr("version") = DDEMAP_VERSION;
    // std::invalid_argument is ValueError (pybind11 does this by default; kept explicit, first)
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const Cancelled&) {  // Interrupted, or the library passing on a search it stopped
            if (!PyErr_Occurred()) PyErr_SetNone(PyExc_KeyboardInterrupt);
        } catch (const std::invalid_argument& e) {
            PyErr_SetString(PyExc_ValueError, e.what());
        }
    });
    m.def(
        "set_progress", [](py::object callback) {
            if (!g_progress) g_progress = new py::object();
            *g_progress = std::move(callback);
        },
        py::arg("callback"), "the progress callback (done, total) of the next calls, or None");
    m.def("roots", &py_roots, py::arg("model"), py::arg("parameters"), py::arg("ring"), py::arg("count"));
    m.def("roots_system", &py_roots_system, py::arg("system"), py::arg("count"), py::arg("degree"), py::arg("solver"));
    m.def("string", &py_string, py::arg("model"), py::arg("parameters"), py::arg("ring"));
    m.def("sweep", &py_sweep, py::arg("model"), py::arg("fixed"), py::arg("x_name"), py::arg("x_axis"), py::arg("y_name"), py::arg("y_axis"),
          py::arg("ring"), py::arg("boundaries"), py::arg("ring_curves"), py::arg("mark"), py::arg("tables"), py::arg("prefix"),
          py::arg("peak"));
    m.def("boundary", &py_boundary, py::arg("model"), py::arg("fixed"), py::arg("x_name"), py::arg("x_axis"), py::arg("y_name"),
          py::arg("y_axis"), py::arg("ring"), py::arg("seed_grid"), py::arg("ring_curves"));
    m.def("classify", &py_classify, py::arg("vehicles"), py::arg("tables"), py::arg("ring"), py::arg("samples"), py::arg("ring_samples"), py::arg("seed"), py::arg("peak"), py::arg("distance"));
    m.def("simulate", &py_simulate, py::arg("fleet"), py::arg("tables"), py::arg("lead_profile"), py::arg("lead"), py::arg("lead_text"),
          py::arg("lead_car"), py::arg("on_event"), py::arg("t_end"), py::arg("step"), py::arg("output_dt"), py::arg("noise_speed"),
          py::arg("noise_gap"), py::arg("seed"));
    m.def("calibrate", &py_calibrate, py::arg("files"), py::arg("follower"), py::arg("joint"), py::arg("car"), py::arg("train"), py::arg("bounds"), py::arg("gap_weight"),
          py::arg("lead_noise"), py::arg("lead_noise_correction"), py::arg("runs"), py::arg("data_dir"), py::arg("report"));
    m.def("mixed_ring", &py_mixed_ring, py::arg("fleet"), py::arg("tables"), py::arg("is_pattern"), py::arg("ring"), py::arg("speed"), py::arg("length"),
          py::arg("solver"), py::arg("count"), py::arg("degree"));
    m.def("mix", &py_mix, py::arg("x"), py::arg("y"), py::arg("tables"), py::arg("ring"), py::arg("p"), py::arg("draws"), py::arg("seed"),
          py::arg("speed"), py::arg("length"), py::arg("solver"));
    m.def("growth", &py_growth, py::arg("vehicles"), py::arg("tables"), py::arg("followers"), py::arg("lead_profile"), py::arg("lead"),
          py::arg("lead_text"), py::arg("lead_car"));
    m.def("design", &py_design, py::arg("car"), py::arg("tables"), py::arg("objective"), py::arg("free"), py::arg("bounds"), py::arg("margin"),
          py::arg("weights"), py::arg("starts"), py::arg("speed"), py::arg("ring"), py::arg("robust"));
    m.def("chart", &py_chart, py::arg("text"), py::arg("source"), py::arg("prefix"));
    m.def("paper", &py_paper, py::arg("prefix"));
    m.def("atlas", &py_atlas, py::arg("text"), py::arg("source"), py::arg("prefix"), py::arg("allow_large"));
    m.def("equilibria", &py_equilibria, py::arg("system"), py::arg("model"), py::arg("ring"), py::arg("parameters"), py::arg("par"),
          py::arg("from_"), py::arg("to"), py::arg("count"), py::arg("max_points"), py::arg("par2"), py::arg("from2"), py::arg("to2"),
          py::arg("branch_point"));
    m.def("hopf", &py_hopf, py::arg("system"), py::arg("model"), py::arg("ring"), py::arg("parameters"), py::arg("par"), py::arg("from_"),
          py::arg("to"), py::arg("par2"), py::arg("from2"), py::arg("to2"), py::arg("max_points"));
    m.def("bistability", &py_bistability, py::arg("system"), py::arg("model"), py::arg("ring"), py::arg("parameters"), py::arg("par"),
          py::arg("from_"), py::arg("to"), py::arg("par2"), py::arg("from2"), py::arg("to2"), py::arg("degree"), py::arg("intervals"),
          py::arg("points"), py::arg("rows"));
    m.def("orbits", &py_orbits, py::arg("system"), py::arg("model"), py::arg("ring"), py::arg("parameters"), py::arg("par"), py::arg("from_"),
          py::arg("to"), py::arg("hopf"), py::arg("degree"), py::arg("intervals"), py::arg("points"), py::arg("adapt"), py::arg("max_step"),
          py::arg("period_doubling"), py::arg("from_simulation"), py::arg("history"), py::arg("guess_times"), py::arg("guess_states"),
          py::arg("guess_label"), py::arg("par2"), py::arg("from2"), py::arg("to2"));
}
