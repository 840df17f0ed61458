#pragma once
/// \file simulate.hpp
/// Nonlinear platoon simulation: a lead car with a prescribed speed profile and followers, each
/// with its own car-following law and delay,
///     s_i' = v_{i-1} - v_i,   v_i' = F_i(s_i(t - tau_i), v_i(t), v_{i-1}(t - tau_i)),
/// starting from equilibrium at the lead's initial speed (s_i = s*_i(v0), v_i = v0 for t <= 0),
/// integrated by DdeSolver (RK4 with a Hermite continuous extension, steps aligned
/// with the lead profile's breakpoints and their first delayed echoes). Events: a follower
/// below its minimum ACC speed disengages; a gap reaching zero is a collision.

#include <memory>
#include <string>
#include <vector>

#include "ddemap/core/execution.hpp"
#include "ddemap/core/status.hpp"
#include "ddemap/traffic/model.hpp"
#include "ddemap/traffic/vehicles.hpp"

namespace ddemap {

/// v_0(t): piecewise linear through (t_k, v_k), constant before the first and after the last.
class LeadProfile {
public:
    LeadProfile(std::vector<double> times, std::vector<double> speeds);
    /// Built-in profiles of the paper's tests: "dip" (22.4 -> 19.7 -> 22.4 m/s, the platoon
    /// test), "oscillatory" (24.5 <-> 21.9 m/s, each held 30 s), "step-low" (11.2 -> 15.6 m/s),
    /// "step-high" (22.4 -> 26.8 m/s); transitions at 0.5 m/s^2 (see describe_builtin()).
    static LeadProfile builtin(const std::string& name);
    static std::vector<std::string> builtin_names();
    static std::string describe_builtin(const std::string& name);
    /// CSV with columns time_s, lead_speed_mps (other columns ignored), or simulate's platoon CSV
    /// (is_platoon_csv()) of which car `car` (0 = its lead, 1..N its followers) becomes the lead;
    /// `car` is required for a platoon CSV and refused for a speed table. Errors name line and column.
    static LeadProfile from_csv(const std::string& text, const std::string& source, int car = -1);

    double speed(double t) const;
    /// integral of v_0 from 0 to t (exact)
    double position(double t) const;
    const std::vector<double>& times() const { return m_t; }
    const std::vector<double>& speeds() const { return m_v; }
    double duration() const { return m_t.back(); }

private:
    std::vector<double> m_t, m_v, m_x;  // m_x: position at m_t
};

/// simulate's CSV read back (columns time_s, car, position_m, speed_mps, gap_m; rows by time, then
/// car 0 = the lead, 1..N the followers): per car its speed and gap at the common times.
struct PlatoonSeries {
    std::string source;
    std::vector<double> time;                     ///< [s], increasing
    std::vector<std::vector<double>> speed, gap;  ///< [car][sample] in m/s and m (gap[0] is empty)
    int followers() const { return static_cast<int>(speed.size()) - 1; }
};
/// true if the CSV's header has simulate's columns car and speed_mps
bool is_platoon_csv(const std::string& text);
/// Reads simulate's CSV; errors name the line (a car missing at a time, times not increasing,
/// negative speeds, a follower without a gap, fewer than one follower).
PlatoonSeries read_platoon_csv(const std::string& text, const std::string& source);

struct SimCar {
    std::shared_ptr<const CarModel> model;
    double min_speed = 0.0;  ///< ACC disengages below this speed [m/s] (0: never)
    std::string name;
};

enum class OnEvent { Continue, Stop };

struct SimOptions {
    double step = 0.05;        ///< largest step [s] (also limited by the smallest delay)
    double t_end = 0.0;        ///< 0: the lead profile's last breakpoint plus 30 s
    double output_dt = 0.1;    ///< output sampling [s]
    OnEvent on_event = OnEvent::Continue;
    /// A follower whose |speed| exceeds this [m/s], or any non-finite state, has diverged: the
    /// simulation stops there with Status::NumericalIssue (no non-finite value is output).
    double max_speed = 1e4;
    /// (simulated time done, t_end), both in milliseconds, after each step (may be empty).
    Progress progress;
    void validate() const;
};

struct SimEvent {
    std::string type;  ///< "disengage" or "collision"
    int car = 0;       ///< follower index, 1 = first follower
    double time = 0.0;
    double speed = 0.0;
    double gap = 0.0;
    double lowest_speed = 0.0;  ///< the car's lowest speed up to the event
};

struct CarSummary {
    int car = 0;
    std::string name;
    double min_speed = 0.0;     ///< lowest speed reached [m/s], before the car's collision if it has one
    double speed_drop = 0.0;    ///< initial speed minus the lowest speed [m/s]
    double min_gap = 0.0;       ///< smallest gap [m], before the car's collision if it has one (then 0)
    std::vector<SimEvent> events;
};

struct SimResult {
    std::vector<double> time;                     ///< output times
    std::vector<std::vector<double>> position;    ///< [car][k], car 0 = lead
    std::vector<std::vector<double>> speed;       ///< [car][k]
    std::vector<std::vector<double>> gap;         ///< [car][k] (car 0: none, empty)
    std::vector<CarSummary> cars;                 ///< followers, platoon order
    std::vector<SimEvent> events;                 ///< in time order
    double initial_speed = 0.0;
    double t_end = 0.0;
    bool stopped = false;                         ///< ended early at an event (OnEvent::Stop)
    std::size_t steps = 0;
    /// Converged, or NumericalIssue when the solution diverged (see SimOptions::max_speed): the
    /// output then ends at t_end, the last step before `diverged_at`, and `message` says why.
    Status status = Status::Converged;
    std::string message;  ///< why the run is trusted (method, steps, no divergence), or why not
    double diverged_at = 0.0;                     ///< time of the step that diverged (0: none)
};

/// Measurement noise on a simulated platoon, as a sensor would add it: independent Gaussian errors
/// of standard deviation `speed_sd` [m/s] on every speed (the lead's included) and `gap_sd` [m]
/// on every gap, drawn from std::mt19937_64(seed) in the order time, car (the same seed gives the
/// same noise on every machine: Box-Muller on the generator's raw 64-bit draws). The dynamics are
/// not changed; positions keep their exact values. std::invalid_argument for a negative or
/// non-finite deviation.
void add_measurement_noise(SimResult& result, double speed_sd, double gap_sd, unsigned long long seed);

/// The size of a simulation, known before it runs: steps ~ t_end / min(step, smallest delay)
/// plus the breakpoints, output samples = t_end / output_dt + 1; memory = the stored steps
/// (2 x 2n + 1 doubles each, x 1.5 for vector growth) + the output arrays (3 (n + 1) doubles
/// per sample) + the files in memory; output = 75 bytes of CSV + 16 of SVG per car and sample.
struct SimEstimate {
    double t_end = 0.0;         ///< the end time the run will use [s]
    double steps = 0.0;
    double samples = 0.0;
    double car_steps = 0.0;     ///< steps x followers (the work)
    double memory_bytes = 0.0;
    double output_bytes = 0.0;
};
SimEstimate estimate_simulation(const LeadProfile& lead, const std::vector<SimCar>& cars, const SimOptions& options = {});

SimResult simulate_platoon(const LeadProfile& lead, const std::vector<SimCar>& cars, const SimOptions& options = {});

/// The one construction of simulated followers (OVRV), in platoon order. The minimum ACC speed
/// rule: every car takes its record's `min_acc_speed`, whatever the source. Built-in settings
/// carry the paper's value (makes A-D: 25 mph = 11.176 m/s; E-G: 0); vehicles read by
/// read_vehicles_csv carry their optional `min_acc_speed` column (default 0: never disengages).
std::vector<SimCar> platoon_from(const std::vector<CalibratedVehicle>& vehicles);

/// `followers` cars of one setting: platoon_from({v, v, ...}).
std::vector<SimCar> platoon_of(const CalibratedVehicle& v, int followers);

}  // namespace ddemap
