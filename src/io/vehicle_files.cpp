#include "ddemap/io/vehicle_files.hpp"

#include <stdexcept>

#include <sys/stat.h>

#include "core/internal/text.hpp"
#include "ddemap/io/files.hpp"
#include "ddemap/traffic/model.hpp"

namespace ddemap {

namespace {

bool ends_with(const std::string& s, const std::string& tail) {
    return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

bool is_fleet_table(const std::string& text, const std::string& source) {
    const detail::CsvReader csv(text, source, "name,k1,k2,th,tau[,eta] or vehicle and/or model, parameter columns, [count]");
    for (const auto& h : csv.header())
        if (h == "vehicle" || h == "model") return true;
    return false;
}

const CalibratedVehicle* builtin(const std::string& name) {
    for (const auto& v : paper_calibration_table())
        if (v.name == name) return &v;
    return nullptr;
}

}  // namespace

bool names_a_file(const std::string& spec) {
    struct stat st {};
    return ends_with(spec, ".csv") || ::stat(spec.c_str(), &st) == 0;
}

Fleet read_fleet_table(const std::string& text, const std::string& source) {
    if (is_fleet_table(text, source)) return read_fleet_csv(text, source);
    Fleet out;
    for (const auto& v : read_vehicles_csv(text, source)) out.push_back({v.name, "ovrv", v.parameters});
    return out;
}

std::vector<CalibratedVehicle> read_vehicle_table(const std::string& text, const std::string& source) {
    if (!is_fleet_table(text, source)) return read_vehicles_csv(text, source);
    std::vector<CalibratedVehicle> out;
    for (const FleetCar& car : read_fleet_csv(text, source)) {
        if (car.model != "ovrv")
            throw std::invalid_argument(source + ": car " + detail::quoted(car.label) + " has model " + detail::quoted(car.model) +
                                        ": expected ovrv cars here (classification and simulation take OVRV vehicles)");
        CalibratedVehicle v;
        if (const CalibratedVehicle* b = builtin(car.label)) v = *b;
        v.name = car.label;
        if (v.vehicle.empty()) v.vehicle = car.label;
        ParameterMap p = car.parameters;
        p["speed"] = 20.0;
        v.parameters = make_model("ovrv", p)->parameters();  // the defaults filled in (eta)
        v.parameters.erase("speed");
        out.push_back(v);
    }
    return out;
}

FleetCar fleet_car_from_argument(const std::string& text) {
    std::string spec = text;
    while (!spec.empty() && (spec.back() == ' ' || spec.back() == '\t')) spec.pop_back();
    while (!spec.empty() && (spec.front() == ' ' || spec.front() == '\t')) spec.erase(0, 1);
    std::string file = spec, name;
    const auto csv = spec.find(".csv:");
    if (csv != std::string::npos) {
        file = spec.substr(0, csv + 4);
        name = spec.substr(csv + 5);
    }
    if (!names_a_file(file)) return parse_fleet_car(spec);
    const Fleet fleet = read_fleet_table(read_text_file(file), file);
    if (!name.empty()) {
        for (const auto& car : fleet)
            if (car.label == name) return car;
        std::string names;
        for (const auto& car : fleet) names += (names.empty() ? "" : ", ") + car.label;
        throw std::invalid_argument("car " + detail::quoted(spec) + ": no car named " + detail::quoted(name) + " in " + file + " (it has " + names + ")");
    }
    for (const auto& car : fleet)
        if (car.model != fleet.front().model || car.parameters != fleet.front().parameters)
            throw std::invalid_argument("car " + detail::quoted(spec) + ": the file holds more than one kind of car: expected FILE.csv:NAME (e.g. " + file + ":" +
                                        fleet.front().label + ")");
    return fleet.front();
}

}  // namespace ddemap
