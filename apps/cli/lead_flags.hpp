#pragma once
// The lead-profile flags shared by simulate and growth: --lead-profile NAME or --lead FILE.csv.
#include <algorithm>
#include <filesystem>
#include <string>

#include "common.hpp"
#include "ddemap/analysis/simulation/simulate.hpp"

namespace ddemap::cli {

struct LeadArgs {
    std::string profile, file;
    void add_to(CLI::App& app) {
        app.add_option("--lead-profile", profile, "built-in lead profile: dip (22.4 -> 19.7 -> 22.4 m/s, the default), oscillatory, step-low, step-high");
        app.add_option("--lead", file,
                       "lead speed CSV with columns time_s, lead_speed_mps (piecewise linear), or P.csv:K: car K of the CSV that simulate "
                       "writes (0 its lead, 1..N its followers)");
    }
    /// The profile; `label` is its name or the file.
    LeadProfile parse(std::string& label) const {
        if (!profile.empty() && !file.empty()) throw BadInput("give either --lead FILE.csv or --lead-profile NAME, not both");
        if (!file.empty()) {
            label = file;
            std::string path = file;
            int car = -1;
            std::error_code ec;
            const auto colon = file.rfind(':');
            if (!std::filesystem::exists(file, ec) && colon != std::string::npos && colon + 1 < file.size() &&
                file.find_first_not_of("0123456789", colon + 1) == std::string::npos) {
                path = file.substr(0, colon);
                const double k = parse_number("--lead " + file, file.substr(colon + 1));
                if (k > 1e6) throw BadInput("--lead = '" + file + "': car " + file.substr(colon + 1) + ": expected a car of the platoon");
                car = static_cast<int>(k);
            }
            return LeadProfile::from_csv(read_input_file("--lead", path), path, car);
        }
        const std::string name = profile.empty() ? "dip" : profile;
        const auto names = LeadProfile::builtin_names();
        if (std::find(names.begin(), names.end(), name) == names.end())
            throw BadInput("--lead-profile = '" + name + "': expected one of dip, oscillatory, step-low, step-high");
        label = name;
        return LeadProfile::builtin(name);
    }
};

}  // namespace ddemap::cli
