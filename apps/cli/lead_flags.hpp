#pragma once
// The lead-profile flags shared by simulate and growth: --lead-profile NAME or --lead FILE.csv.
#include <algorithm>
#include <string>

#include "common.hpp"
#include "ddemap/analysis/simulation/simulate.hpp"

namespace ddemap::cli {

struct LeadArgs {
    std::string profile, file;
    void add_to(CLI::App& app) {
        app.add_option("--lead-profile", profile, "built-in lead profile: dip (22.4 -> 19.7 -> 22.4 m/s, the default), oscillatory, step-low, step-high");
        app.add_option("--lead", file, "lead speed CSV with columns time_s, lead_speed_mps (piecewise linear)");
    }
    /// The profile; `label` is its name or the file.
    LeadProfile parse(std::string& label) const {
        if (!profile.empty() && !file.empty()) throw BadInput("give either --lead FILE.csv or --lead-profile NAME, not both");
        if (!file.empty()) {
            label = file;
            return LeadProfile::from_csv(read_input_file("--lead", file), file);
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
