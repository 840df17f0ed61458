#include "ddemap/analysis/simulation/simulate.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <random>
#include <sstream>
#include <stdexcept>

#include "ddemap/solve/integrate.hpp"
#include "ddemap/traffic/fleet.hpp"
#include "core/internal/text.hpp"

namespace ddemap {

LeadProfile::LeadProfile(std::vector<double> times, std::vector<double> speeds) : m_t(std::move(times)), m_v(std::move(speeds)) {
    if (m_t.empty() || m_t.size() != m_v.size()) throw std::invalid_argument("lead profile: expected as many times as speeds, at least one");
    for (std::size_t i = 0; i < m_t.size(); ++i) {
        if (!std::isfinite(m_t[i]) || !std::isfinite(m_v[i])) throw std::invalid_argument("lead profile: non-finite value at sample " + std::to_string(i + 1));
        // positions are integrated from the times: beyond 1e9 s (32 years) they leave the precision a platoon needs
        if (std::abs(m_t[i]) > 1e9)
            throw std::invalid_argument("lead profile: time " + detail::format_number(m_t[i]) + " at sample " + std::to_string(i + 1) +
                                        ": expected -1e9 to 1e9 s");
        if (m_v[i] < 0.0 || m_v[i] > kMaxRoadSpeed)
            throw std::invalid_argument("lead profile: speed " + detail::format_number(m_v[i]) + " at t = " + detail::format_number(m_t[i]) +
                                        ": expected 0 to 100 m/s (360 km/h; a speed in km/h? divide by 3.6)");
        if (i > 0 && !(m_t[i] > m_t[i - 1])) {
            throw std::invalid_argument("lead profile: time " + detail::format_number(m_t[i]) + " after " + detail::format_number(m_t[i - 1]) + ": expected increasing times");
        }
    }
    if (m_t.front() > 0.0) {
        m_t.insert(m_t.begin(), 0.0);
        m_v.insert(m_v.begin(), m_v.front());
    }
    m_x.resize(m_t.size());
    m_x[0] = m_t[0] * m_v[0];  // position 0 at t = 0 (the profile is constant before m_t[0])
    for (std::size_t i = 1; i < m_t.size(); ++i) m_x[i] = m_x[i - 1] + 0.5 * (m_v[i] + m_v[i - 1]) * (m_t[i] - m_t[i - 1]);
    const double shift = position(0.0);
    for (auto& x : m_x) x -= shift;
}

double LeadProfile::speed(double t) const {
    if (t <= m_t.front()) return m_v.front();
    if (t >= m_t.back()) return m_v.back();
    const std::size_t k = static_cast<std::size_t>(std::upper_bound(m_t.begin(), m_t.end(), t) - m_t.begin()) - 1;
    const double s = (t - m_t[k]) / (m_t[k + 1] - m_t[k]);
    return m_v[k] + s * (m_v[k + 1] - m_v[k]);
}

double LeadProfile::position(double t) const {
    if (t <= m_t.front()) return m_x.front() - (m_t.front() - t) * m_v.front();
    if (t >= m_t.back()) return m_x.back() + (t - m_t.back()) * m_v.back();
    const std::size_t k = static_cast<std::size_t>(std::upper_bound(m_t.begin(), m_t.end(), t) - m_t.begin()) - 1;
    const double dt = t - m_t[k];
    const double a = (m_v[k + 1] - m_v[k]) / (m_t[k + 1] - m_t[k]);
    return m_x[k] + m_v[k] * dt + 0.5 * a * dt * dt;
}

std::vector<std::string> LeadProfile::builtin_names() { return {"dip", "oscillatory", "step-low", "step-high"}; }

namespace {
/// Holds and ramps at 0.5 m/s^2: speeds[i] held for holds[i] seconds, then a ramp to speeds[i+1].
LeadProfile ramps(const std::vector<double>& speeds, const std::vector<double>& holds) {
    std::vector<double> t{0.0}, v{speeds[0]};
    double now = 0.0;
    for (std::size_t i = 0; i < speeds.size(); ++i) {
        now += holds[i];
        t.push_back(now);
        v.push_back(speeds[i]);
        if (i + 1 < speeds.size()) {
            now += std::abs(speeds[i + 1] - speeds[i]) / 0.5;
            t.push_back(now);
            v.push_back(speeds[i + 1]);
        }
    }
    return LeadProfile(t, v);
}
}  // namespace

std::string LeadProfile::describe_builtin(const std::string& name) {
    if (name == "dip") return "22.4 m/s for 20 s, down to 19.7 m/s (6 mph dip), held 5 s, back to 22.4 m/s, held 60 s; ramps 0.5 m/s^2";
    if (name == "oscillatory") return "24.5 and 21.9 m/s alternately, each held 30 s, three cycles; ramps 0.5 m/s^2";
    if (name == "step-low") return "11.2 m/s for 20 s, up to 15.6 m/s, held 60 s; ramp 0.5 m/s^2";
    if (name == "step-high") return "22.4 m/s for 20 s, up to 26.8 m/s, held 60 s; ramp 0.5 m/s^2";
    throw std::invalid_argument("lead profile " + detail::quoted(name) + ": expected one of dip, oscillatory, step-low, step-high");
}

LeadProfile LeadProfile::builtin(const std::string& name) {
    describe_builtin(name);  // validates the name
    if (name == "dip") return ramps({22.4, 19.7, 22.4}, {20, 5, 60});
    if (name == "oscillatory") return ramps({24.5, 21.9, 24.5, 21.9, 24.5, 21.9}, {30, 30, 30, 30, 30, 30});
    if (name == "step-low") return ramps({11.2, 15.6}, {20, 60});
    return ramps({22.4, 26.8}, {20, 60});
}

bool is_platoon_csv(const std::string& text) {
    try {
        detail::CsvReader csv(text, "", "");
        return csv.column("car", false) >= 0 && csv.column("speed_mps", false) >= 0;
    } catch (const std::invalid_argument&) {
        return false;
    }
}

PlatoonSeries read_platoon_csv(const std::string& text, const std::string& source) {
    detail::CsvReader csv(text, source, "time_s, car, speed_mps, gap_m (the CSV that simulate writes)");
    const int it = csv.column("time_s"), ic = csv.column("car"), iv = csv.column("speed_mps"), ig = csv.column("gap_m");
    PlatoonSeries p;
    p.source = source;
    std::size_t expected_car = 0;  // the car the next row must hold
    while (csv.next()) {
        const double t = csv.number(it, "time_s");
        const double c = csv.number(ic, "car");
        if (!(c >= 0 && c == std::floor(c) && c <= 1e6)) csv.fail("column 'car' = " + detail::format_number(c) + ": expected a car number 0, 1, 2, ...");
        const auto car = static_cast<std::size_t>(c);
        if (car == 0) {
            if (!p.time.empty() && expected_car != p.speed.size())
                csv.fail("car 0 at time_s = " + detail::format_number(t) + ": expected car " + std::to_string(expected_car) +
                         " of time_s = " + detail::format_number(p.time.back()) + " first (every time lists cars 0 to N)");
            if (!p.time.empty() && !(t > p.time.back()))
                csv.fail("time_s = " + detail::format_number(t) + " after " + detail::format_number(p.time.back()) + ": expected increasing times");
            p.time.push_back(t);
            if (p.time.size() == 1) {
                p.speed.emplace_back();
                p.gap.emplace_back();
            }
            expected_car = 0;
        } else if (p.time.empty()) {
            csv.fail("car " + std::to_string(car) + " before car 0: expected each time to start with the lead (car 0)");
        }
        if (p.time.size() == 1 && car == p.speed.size()) {  // the first time defines the platoon
            p.speed.emplace_back();
            p.gap.emplace_back();
        }
        if (car != expected_car || car >= p.speed.size())
            csv.fail("car " + std::to_string(car) + " at time_s = " + detail::format_number(t) + ": expected car " + std::to_string(expected_car) +
                     " (every time lists cars 0 to N in order)");
        if (t != p.time.back()) csv.fail("time_s = " + detail::format_number(t) + ": expected " + detail::format_number(p.time.back()) + " as car 0 of this time");
        const double v = csv.number(iv, "speed_mps");
        if (v < 0.0 || v > kMaxRoadSpeed) csv.fail("speed_mps = " + detail::format_number(v) + ": expected 0 to 100 m/s (360 km/h)");
        p.speed[car].push_back(v);
        if (car > 0) p.gap[car].push_back(csv.number(ig, "gap_m"));
        ++expected_car;
    }
    if (p.time.empty()) throw std::invalid_argument(source + ": no rows: expected the CSV that simulate writes");
    if (expected_car != p.speed.size())
        throw std::invalid_argument(source + ": the last time lists " + std::to_string(expected_car) + " of " + std::to_string(p.speed.size()) +
                                    " cars: expected every time to list cars 0 to N (a truncated file?)");
    if (p.followers() < 1) throw std::invalid_argument(source + ": only the lead (car 0): expected at least one follower");
    return p;
}

LeadProfile LeadProfile::from_csv(const std::string& text, const std::string& source, int car) {
    if (is_platoon_csv(text)) {
        const PlatoonSeries p = read_platoon_csv(text, source);
        if (car < 0)
            throw std::invalid_argument(source + " is a platoon (simulate's CSV, cars 0 to " + std::to_string(p.followers()) +
                                        "): name the car that leads, e.g. " + source + ":" + std::to_string(p.followers()));
        if (car > p.followers())
            throw std::invalid_argument(source + ": car " + std::to_string(car) + ": expected 0 to " + std::to_string(p.followers()));
        if (p.time.size() < 2) throw std::invalid_argument(source + ": expected at least two samples");
        return LeadProfile(p.time, p.speed[static_cast<std::size_t>(car)]);
    }
    if (car >= 0) throw std::invalid_argument(source + ":" + std::to_string(car) + ": a car number is taken only from a platoon CSV (simulate's), not from a lead speed table");
    detail::CsvReader csv(text, source, "time_s, lead_speed_mps");
    const int it = csv.column("time_s"), iv = csv.column("lead_speed_mps");
    std::vector<double> t, v;
    while (csv.next()) {
        t.push_back(csv.number(it, "time_s"));
        v.push_back(csv.number(iv, "lead_speed_mps"));
        if (t.size() > 1 && !(t.back() > t[t.size() - 2])) {
            csv.fail("time_s = " + detail::format_number(t.back()) + ": expected increasing times");
        }
        if (v.back() < 0.0 || v.back() > kMaxRoadSpeed)
            csv.fail("lead_speed_mps = " + detail::format_number(v.back()) + ": expected 0 to 100 m/s (360 km/h; a speed in km/h? divide by 3.6)");
    }
    if (t.size() < 2) throw std::invalid_argument(source + ": expected at least two samples");
    return LeadProfile(t, v);
}

void SimOptions::validate() const {
    if (!(std::isfinite(step) && step > 0.0 && step <= 1.0)) throw std::invalid_argument("step = " + detail::format_number(step) + ": expected 0 < step <= 1 s");
    if (!(std::isfinite(t_end) && t_end >= 0.0)) throw std::invalid_argument("t_end = " + detail::format_number(t_end) + ": expected >= 0");
    if (!(std::isfinite(output_dt) && output_dt > 0.0)) throw std::invalid_argument("output_dt = " + detail::format_number(output_dt) + ": expected > 0");
    if (!(std::isfinite(max_speed) && max_speed > 0.0)) throw std::invalid_argument("max_speed = " + detail::format_number(max_speed) + ": expected > 0");
}

void add_measurement_noise(SimResult& result, double speed_sd, double gap_sd, unsigned long long seed) {
    for (const auto& [what, sd] : {std::pair<const char*, double>{"speed", speed_sd}, {"gap", gap_sd}})
        if (!(std::isfinite(sd) && sd >= 0.0))
            throw std::invalid_argument(std::string("noise on the ") + what + " = " + detail::format_number(sd) + ": expected a finite standard deviation >= 0");
    std::mt19937_64 gen(seed);
    // Box-Muller from 53-bit uniforms in (0, 1]: portable, unlike std::normal_distribution
    const auto uniform = [&gen] { return (static_cast<double>(gen() >> 11) + 1.0) * 0x1.0p-53; };
    const double two_pi = 6.283185307179586;
    const auto normal = [&] { return std::sqrt(-2.0 * std::log(uniform())) * std::cos(two_pi * uniform()); };
    for (std::size_t k = 0; k < result.time.size(); ++k)
        for (std::size_t c = 0; c < result.speed.size(); ++c) {
            const double ev = normal(), eg = normal();
            if (speed_sd > 0.0) result.speed[c][k] += speed_sd * ev;
            if (c > 0 && gap_sd > 0.0 && k < result.gap[c].size()) result.gap[c][k] += gap_sd * eg;
        }
}

SimEstimate estimate_simulation(const LeadProfile& lead, const std::vector<SimCar>& cars, const SimOptions& options) {
    options.validate();
    SimEstimate e;
    const double n = static_cast<double>(cars.size());
    double h = options.step;
    for (const auto& c : cars)
        if (c.model && c.model->delay() > 0.0) h = std::min(h, c.model->delay());
    e.t_end = options.t_end > 0.0 ? options.t_end : lead.duration() + 30.0;
    const double marks = static_cast<double>(lead.times().size()) * (1.0 + n);
    e.steps = std::ceil(e.t_end / h) + marks;
    e.samples = std::floor(e.t_end / options.output_dt) + 1.0;
    e.car_steps = e.steps * std::max(n, 1.0);
    e.output_bytes = e.samples * (n + 1.0) * (75.0 + 16.0);
    e.memory_bytes = e.steps * (4.0 * n + 1.0) * 8.0 * 1.5 + marks * 16.0 + e.samples * (3.0 * (n + 1.0) + 1.0) * 8.0 + 2.0 * e.output_bytes;
    return e;
}

std::vector<SimCar> platoon_from(const std::vector<CalibratedVehicle>& vehicles) {
    std::vector<SimCar> cars;
    for (const auto& v : vehicles) {
        std::shared_ptr<const CarModel> m = make_model("ovrv", v.parameters);
        cars.push_back({m, v.min_acc_speed, v.name});
    }
    return cars;
}

std::vector<SimCar> platoon_of(const CalibratedVehicle& v, int followers) {
    return platoon_from(std::vector<CalibratedVehicle>(static_cast<std::size_t>(std::max(followers, 0)), v));
}


SimResult simulate_platoon(const LeadProfile& lead, const std::vector<SimCar>& cars, const SimOptions& options) {
    options.validate();
    if (cars.empty()) throw std::invalid_argument("a platoon needs at least one follower");
    const int n = static_cast<int>(cars.size());
    const double v0 = lead.speed(0.0);
    std::vector<double> s_eq(n), tau(n);
    double h = options.step;
    for (int i = 0; i < n; ++i) {
        if (!cars[i].model) throw std::invalid_argument("follower " + std::to_string(i + 1) + " has no model");
        if (cars[i].model->leaders() > 1)
            throw std::invalid_argument("follower " + std::to_string(i + 1) + ": model " + cars[i].model->name() +
                                        " uses " + std::to_string(cars[i].model->leaders()) +
                                        " cars ahead; the platoon simulation supports laws of the car ahead only");
        s_eq[i] = cars[i].model->equilibrium_gap(v0);
        tau[i] = cars[i].model->delay();
        if (tau[i] > 0.0) h = std::min(h, tau[i]);
        if (!(s_eq[i] > 0.0) || !std::isfinite(s_eq[i])) {
            throw std::invalid_argument("follower " + std::to_string(i + 1) + ": no positive equilibrium gap at the lead's initial speed " + detail::format_number(v0) + " m/s");
        }
    }
    const double t_end = options.t_end > 0.0 ? options.t_end : lead.duration() + 30.0;

    // state: (s_1, v_1, ..., s_n, v_n)
    auto history = [&](double, double* y) {
        for (int i = 0; i < n; ++i) {
            y[2 * i] = s_eq[i];
            y[2 * i + 1] = v0;
        }
    };
    auto rhs = [&](double t, const double* y, const DdeSolver& sol, double* dy) {
        for (int i = 0; i < n; ++i) {
            const double v_ahead = i == 0 ? lead.speed(t) : y[2 * i - 1];
            dy[2 * i] = v_ahead - y[2 * i + 1];
            const double td = t - tau[i];
            double gap_d, lead_d;
            if (tau[i] == 0.0) {
                gap_d = y[2 * i];
                lead_d = v_ahead;
            } else {
                gap_d = sol.value(2 * i, td);
                lead_d = i == 0 ? lead.speed(td) : sol.value(2 * i - 1, td);
            }
            const double in[3] = {gap_d, y[2 * i + 1], lead_d};  // one leader (checked above)
            dy[2 * i + 1] = cars[i].model->acceleration(in);
        }
    };
    DdeSolver solver(2 * n, 0.0, history, rhs);

    SimResult r;
    r.initial_speed = v0;
    r.cars.resize(n);
    for (int i = 0; i < n; ++i) {
        r.cars[i].car = i + 1;
        r.cars[i].name = cars[i].name;
        r.cars[i].min_speed = v0;
        r.cars[i].min_gap = s_eq[i];
    }
    std::vector<char> disengaged(n, 0), collided(n, 0);
    std::vector<double> prev(solver.state(), solver.state() + 2 * n);
    double t_prev = 0.0;
    bool stop = false;
    const long progress_total = static_cast<long>(std::min(t_end * 1e3, 9e15));
    auto after = [&](const DdeSolver& sol) {
        const double t = sol.time();
        const double* y = sol.state();
        for (int i = 0; i < 2 * n; ++i) {
            const bool speed = i % 2 == 1;
            if (!std::isfinite(y[i]) || (speed && std::abs(y[i]) > options.max_speed)) {
                r.status = Status::NumericalIssue;
                r.diverged_at = t;
                r.message = "the solution diverged at t = " + detail::format_number(t) + " s: follower " + std::to_string(i / 2 + 1) + "'s " +
                            (speed ? "speed" : "gap") + " reached " + detail::format_number(y[i]) + (speed ? " m/s" : " m") +
                            " (|speed| above " + detail::format_number(options.max_speed) +
                            " m/s or a non-finite state); the output ends at the last step before, t = " + detail::format_number(t_prev) + " s";
                return false;
            }
        }
        if (options.progress) options.progress(static_cast<long>(std::min(t * 1e3, 9e15)), progress_total);
        for (int i = 0; i < n; ++i) {
            const double s = y[2 * i], v = y[2 * i + 1];
            auto& c = r.cars[i];
            // the summary is of the physical part: up to the car's first collision (the law goes on
            // through it, the cars passing each other, and its later values mean nothing)
            if (!collided[i] && v < c.min_speed) c.min_speed = v;
            if (!collided[i] && s < c.min_gap) c.min_gap = std::max(s, 0.0);
            auto crossing = [&](double a, double b, double level) {  // time where a -> b crosses level
                const double f = (a - level) / (a - b);
                return t_prev + std::clamp(f, 0.0, 1.0) * (t - t_prev);
            };
            if (!disengaged[i] && cars[i].min_speed > 0.0 && v < cars[i].min_speed) {
                disengaged[i] = 1;
                SimEvent e{"disengage", i + 1, crossing(prev[2 * i + 1], v, cars[i].min_speed), cars[i].min_speed, s, c.min_speed};
                c.events.push_back(e);
                r.events.push_back(e);
                if (options.on_event == OnEvent::Stop) stop = true;
            }
            if (!collided[i] && s <= 0.0) {
                collided[i] = 1;
                SimEvent e{"collision", i + 1, crossing(prev[2 * i], s, 0.0), v, 0.0, c.min_speed};
                c.events.push_back(e);
                r.events.push_back(e);
                if (options.on_event == OnEvent::Stop) stop = true;
            }
        }
        std::copy(y, y + 2 * n, prev.begin());
        t_prev = t;
        return !stop;
    };
    // steps land on the lead's breakpoints and their first echoes t_b + tau_i
    std::vector<double> marks;
    for (double b : lead.times()) {
        marks.push_back(b);
        for (double d : tau)
            if (d > 0.0) marks.push_back(b + d);
    }
    solver.integrate(t_end, h, marks, after);
    r.stopped = stop;
    r.t_end = r.status == Status::Converged ? solver.time() : t_prev;
    r.steps = solver.steps();
    if (r.status == Status::Converged)
        r.message = "integrated to t = " + detail::format_number(r.t_end) + " s in " + std::to_string(r.steps) + " steps of at most " +
                    detail::format_number(h) +
                    " s (classical Runge-Kutta of order 4, delayed values by cubic Hermite interpolation, steps landing on the lead's "
                    "breakpoints); the state stayed finite and below the divergence bound";
    std::sort(r.events.begin(), r.events.end(), [](const SimEvent& a, const SimEvent& b) { return a.time < b.time; });
    {
        const auto first = std::find_if(r.events.begin(), r.events.end(), [](const SimEvent& e) { return e.type == "collision"; });
        const long collisions = std::count_if(r.events.begin(), r.events.end(), [](const SimEvent& e) { return e.type == "collision"; });
        if (first != r.events.end())
            r.message += "; " + std::to_string(collisions) + (collisions == 1 ? " car collided" : " cars collided") + " (the first, car " +
                         std::to_string(first->car) + ", at t = " + detail::significant(first->time, 4) + " s)" +
                         (r.stopped ? ": the run stopped there"
                                    : ": the law goes on through a collision (the cars pass each other), so each car's values after its "
                                      "collision are not physical; its lowest speed and smallest gap are those before it");
    }
    for (auto& c : r.cars) c.speed_drop = v0 - c.min_speed;

    // output on a regular grid (continuous extension)
    const int samples = static_cast<int>(std::floor(r.t_end / options.output_dt + 1e-9)) + 1;
    r.position.assign(n + 1, std::vector<double>(samples));
    r.speed.assign(n + 1, std::vector<double>(samples));
    r.gap.assign(n + 1, std::vector<double>());
    for (int i = 1; i <= n; ++i) r.gap[i].resize(samples);
    for (int k = 0; k < samples; ++k) {
        const double t = std::min(k * options.output_dt, r.t_end);
        r.time.push_back(t);
        r.position[0][k] = lead.position(t);
        r.speed[0][k] = lead.speed(t);
        // after a divergence the stored step past t_end is not finite: the last sample takes
        // the state at t_end itself
        const bool last_good = r.status != Status::Converged && t >= r.t_end;
        for (int i = 1; i <= n; ++i) {
            const double s = last_good ? prev[2 * (i - 1)] : solver.value(2 * (i - 1), t);
            r.gap[i][k] = s;
            r.speed[i][k] = last_good ? prev[2 * (i - 1) + 1] : solver.value(2 * (i - 1) + 1, t);
            r.position[i][k] = r.position[i - 1][k] - s;
        }
    }
    return r;
}

}  // namespace ddemap
