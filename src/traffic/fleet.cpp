#include "ddemap/traffic/fleet.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <stdexcept>

#include "ddemap/solve/roots.hpp"
#include "ddemap/traffic/transfer_function.hpp"
#include "ddemap/traffic/vehicles.hpp"
#include "core/internal/text.hpp"

namespace ddemap {

namespace {

using detail::trim;

const CalibratedVehicle* find_vehicle(const std::string& name) {
    for (const auto& v : paper_calibration_table())
        if (v.name == name) return &v;
    return nullptr;
}

std::string vehicle_names() {
    std::string s;
    for (const auto& v : paper_calibration_table()) s += (s.empty() ? "" : ", ") + v.name;
    return s;
}

/// Distinct (model, parameters) of a fleet, each built once (speed 0: only s*(v) and the law are used).
struct Types {
    std::vector<std::unique_ptr<CarModel>> models;
    std::vector<int> of_car;
};

Types types_of(const Fleet& fleet, double speed) {
    Types t;
    std::map<std::pair<std::string, ParameterMap>, int> index;
    for (const auto& car : fleet) {
        ParameterMap p = car.parameters;
        if (p.count("speed")) throw std::invalid_argument("car " + car.label + ": the speed is set by the ring, not per car");
        p["speed"] = speed;
        auto key = std::make_pair(car.model, p);
        auto it = index.find(key);
        if (it == index.end()) {
            try {
                t.models.push_back(make_model(car.model, p));
            } catch (const std::invalid_argument& e) {
                throw std::invalid_argument("car " + car.label + ": " + e.what());
            }
            it = index.emplace(key, static_cast<int>(t.models.size()) - 1).first;
        }
        t.of_car.push_back(it->second);
    }
    return t;
}

double gap_sum(const Types& t, double v, std::vector<double>* gaps) {
    std::vector<double> per(t.models.size());
    for (std::size_t k = 0; k < t.models.size(); ++k) per[k] = t.models[k]->equilibrium_gap(v);
    double sum = 0.0;
    if (gaps) gaps->clear();
    for (int k : t.of_car) {
        sum += per[k];
        if (gaps) gaps->push_back(per[k]);
    }
    return sum;
}

void check_fleet(const Fleet& fleet) {
    if (fleet.size() < 2) throw std::invalid_argument("a ring needs at least 2 cars, got " + std::to_string(fleet.size()));
    if (fleet.size() > 1000000) throw std::invalid_argument("a ring of " + std::to_string(fleet.size()) + " cars: expected at most 1000000");
}

}  // namespace

Fleet fleet_from_pattern(const std::string& pattern, int cars) {
    if (cars < 0 || cars > 1000000) throw std::invalid_argument("cars = " + std::to_string(cars) + ": expected 0 (the pattern once) or 2..1000000");
    Fleet unit;
    std::size_t start = 0;
    while (start <= pattern.size()) {
        const std::size_t comma = pattern.find(',', start);
        const std::string token = trim(pattern.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
        start = comma == std::string::npos ? pattern.size() + 1 : comma + 1;
        if (token.empty()) throw std::invalid_argument("fleet pattern " + detail::quoted(pattern) + ": empty entry; expected NAME or NAME*COUNT separated by commas");
        std::string name = token;
        long repeat = 1;
        const auto star = token.find('*');
        if (star != std::string::npos) {
            name = trim(token.substr(0, star));
            const std::string k = trim(token.substr(star + 1));
            char* end = nullptr;
            repeat = std::strtol(k.c_str(), &end, 10);
            if (k.empty() || *end != '\0' || repeat < 1 || repeat > 1000000)
                throw std::invalid_argument("fleet pattern entry " + detail::quoted(token) + ": expected NAME*COUNT with COUNT an integer 1..1000000");
        }
        const CalibratedVehicle* v = find_vehicle(name);
        if (!v) throw std::invalid_argument("fleet pattern entry " + detail::quoted(name) + ": expected a calibrated vehicle (" + vehicle_names() + ")");
        if (unit.size() + static_cast<std::size_t>(repeat) > 1000000) throw std::invalid_argument("fleet pattern " + detail::quoted(pattern) + ": more than 1000000 cars");
        for (long r = 0; r < repeat; ++r) unit.push_back({v->name, "ovrv", v->parameters});
    }
    if (cars == 0) return unit;
    Fleet out;
    out.reserve(cars);
    for (int i = 0; i < cars; ++i) out.push_back(unit[i % unit.size()]);
    return out;
}

Fleet read_fleet_csv(const std::string& text, const std::string& source) {
    Fleet out;
    for (const CalibratedVehicle& v : read_car_table(text, source)) out.push_back({v.name, v.model, v.parameters});
    return out;
}

FleetCar parse_fleet_car(const std::string& text) {
    const std::string spec = trim(text);
    const auto colon = spec.find(':');
    if (colon == std::string::npos) {
        const CalibratedVehicle* v = find_vehicle(spec);
        if (!v) throw std::invalid_argument("car " + detail::quoted(spec) + ": expected a calibrated vehicle (" + vehicle_names() + ") or MODEL:NAME=VALUE,...");
        return {v->name, "ovrv", v->parameters};
    }
    FleetCar car;
    car.model = trim(spec.substr(0, colon));
    car.label = spec;
    std::size_t start = colon + 1;
    while (start < spec.size()) {
        const std::size_t comma = spec.find(',', start);
        const std::string item = trim(spec.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
        start = comma == std::string::npos ? spec.size() : comma + 1;
        const auto eq = item.find('=');
        double value = 0.0;
        if (eq == std::string::npos || !detail::parse_finite(trim(item.substr(eq + 1)), value))
            throw std::invalid_argument("car " + detail::quoted(spec) + ": entry " + detail::quoted(item) + ": expected NAME=VALUE with a finite number");
        const std::string name = trim(item.substr(0, eq));
        if (name == "speed") throw std::invalid_argument("car " + detail::quoted(spec) + ": the speed is set by the ring, not per car");
        car.parameters[name] = value;
    }
    ParameterMap p = car.parameters;
    p["speed"] = 0.0;
    try {
        (void)make_model(car.model, p);
    } catch (const std::invalid_argument& e) {
        throw std::invalid_argument("car " + detail::quoted(spec) + ": " + e.what());
    }
    return car;
}

std::vector<Linearisation> linearise_fleet(const Fleet& fleet, double speed) {
    const Types t = types_of(fleet, speed);
    std::vector<Linearisation> per;
    for (const auto& m : t.models) per.push_back(m->linearise());
    std::vector<Linearisation> out;
    out.reserve(fleet.size());
    for (int k : t.of_car) out.push_back(per[k]);
    return out;
}

RingEquilibrium ring_equilibrium_at_speed(const Fleet& fleet, double speed) {
    check_fleet(fleet);
    if (!(std::isfinite(speed) && speed >= 0.0)) throw std::invalid_argument("speed = " + detail::format_number(speed) + ": expected a finite speed >= 0 m/s");
    const Types t = types_of(fleet, speed);
    RingEquilibrium e;
    e.speed = speed;
    e.length = gap_sum(t, speed, &e.gaps);
    for (std::size_t i = 0; i < e.gaps.size(); ++i)
        if (!(std::isfinite(e.gaps[i]) && e.gaps[i] > 0.0))
            throw std::invalid_argument("car " + std::to_string(i + 1) + " (" + fleet[i].label + ") has no positive equilibrium gap at speed " + detail::format_number(speed) + " m/s");
    return e;
}

RingEquilibrium ring_equilibrium_at_length(const Fleet& fleet, double length) {
    check_fleet(fleet);
    if (!(std::isfinite(length) && length > 0.0)) throw std::invalid_argument("length = " + detail::format_number(length) + ": expected a finite ring length > 0 m");
    const Types t = types_of(fleet, 0.0);
    double cap = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < t.models.size(); ++k) {
        const ParameterMap p = t.models[k]->parameters();
        if (p.count("v0")) cap = std::min(cap, p.at("v0"));
    }
    const double g0 = gap_sum(t, 0.0, nullptr);
    if (length < g0)
        throw std::invalid_argument("length = " + detail::format_number(length) + " m: expected at least " + detail::format_number(g0) +
                                    " m, the sum of the standstill gaps");
    double lo = 0.0, hi = std::isfinite(cap) ? cap * (1.0 - 1e-12) : 1.0;
    if (!std::isfinite(cap)) {
        while (gap_sum(t, hi, nullptr) < length && hi < 1e6) hi *= 2.0;
    }
    if (gap_sum(t, hi, nullptr) < length)
        throw std::invalid_argument("length = " + detail::format_number(length) + " m: no common speed below " + detail::format_number(hi) +
                                    " m/s spaces the cars that far apart");
    for (int i = 0; i < 200 && hi - lo > 1e-15 * std::max(1.0, hi); ++i) {
        const double mid = 0.5 * (lo + hi);
        (gap_sum(t, mid, nullptr) < length ? lo : hi) = mid;
    }
    const double v = gap_sum(t, hi, nullptr) - length < length - gap_sum(t, lo, nullptr) ? hi : lo;
    return ring_equilibrium_at_speed(fleet, v);
}

LinearDDE mixed_ring_dde(const std::vector<Linearisation>& cars) {
    const int n = static_cast<int>(cars.size());
    if (n < 2) throw std::invalid_argument("a ring needs at least 2 cars, got " + std::to_string(n));
    using T = Eigen::Triplet<double>;
    std::vector<T> a0;
    std::map<double, std::vector<T>> by_delay;
    auto place = [&](const ExpPoly& e, int row, int col) {
        for (const auto& t : e.terms()) {
            if (t.delay == 0.0)
                a0.emplace_back(row, col, t.coef);
            else
                by_delay[t.delay].emplace_back(row, col, t.coef);
        }
    };
    for (int i = 0; i < n; ++i) {
        const int s = 2 * i, v = 2 * i + 1, va = 2 * ((i + n - 1) % n) + 1;
        a0.emplace_back(s, va, 1.0);
        a0.emplace_back(s, v, -1.0);
        place(cars[i].gap, v, s);
        place(cars[i].own, v, v);
        place(cars[i].lead, v, va);
        for (std::size_t j = 0; j < cars[i].further.size(); ++j) {
            const int far = ((i - 2 - static_cast<int>(j)) % n + n) % n;
            place(cars[i].further[j], v, 2 * far + 1);
        }
    }
    SparseMatrixXd m0(2 * n, 2 * n);
    m0.setFromTriplets(a0.begin(), a0.end());
    std::vector<SparseDelayTerm> terms;
    for (auto& [delay, trip] : by_delay) {
        SparseDelayTerm term;
        term.delay = delay;
        term.matrix.resize(2 * n, 2 * n);
        term.matrix.setFromTriplets(trip.begin(), trip.end());
        terms.push_back(std::move(term));
    }
    return LinearDDE(std::move(m0), std::move(terms));
}

double ring_product_residual(const std::vector<Linearisation>& cars, cplx lambda) {
    cplx sum = 0.0;
    for (const auto& c : cars) {
        cplx num, den;
        TransferFunction(c).evaluate(lambda, num, den);  // (refuses a car with more than one leader)
        sum += std::log(num) - std::log(den);
    }
    return std::abs(std::exp(sum) - 1.0);
}

Fleet mixed_fleet(const FleetCar& x, const FleetCar& y, int cars, int x_cars, int draw, unsigned seed) {
    if (cars < 2 || cars > 1000000) throw std::invalid_argument("cars = " + std::to_string(cars) + ": expected 2..1000000");
    if (x_cars < 0 || x_cars > cars) throw std::invalid_argument("x_cars = " + std::to_string(x_cars) + ": expected 0.." + std::to_string(cars));
    std::vector<bool> is_x(cars, false);
    if (draw == 0) {
        for (long i = 0; i < cars; ++i) is_x[i] = ((i + 1) * x_cars) / cars > (i * x_cars) / cars;
    } else {
        for (int i = 0; i < x_cars; ++i) is_x[i] = true;
        std::mt19937 rng(seed + static_cast<unsigned>(draw));
        for (int i = cars - 1; i > 0; --i) {  // Fisher-Yates with the generator's raw output (portable)
            const int j = static_cast<int>(rng() % static_cast<unsigned>(i + 1));
            const bool t = is_x[i];
            is_x[i] = is_x[j];
            is_x[j] = t;
        }
    }
    Fleet f;
    f.reserve(cars);
    for (int i = 0; i < cars; ++i) f.push_back(is_x[i] ? x : y);
    return f;
}

}  // namespace ddemap
