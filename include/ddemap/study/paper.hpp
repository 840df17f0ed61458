#pragma once
/// \file paper.hpp
/// The seed paper's main job, the computations that need no chart spec: the built-in
/// calibration table classified (plant, ring of N cars, string) and the disturbance growth
/// behind a built-in lead profile. The stability charts come from chart specs (io/paper.hpp).

#include <string>
#include <vector>

#include "ddemap/analysis/stability/classify.hpp"
#include "ddemap/study/growth.hpp"

namespace ddemap {

struct PaperStudyOptions {
    int cars = 22;             ///< ring size of the classification (0 = infinity)
    std::string lead = "dip";  ///< built-in lead profile of the growth study
    int followers = 15;        ///< longest platoon of the growth study
};

struct PaperStudy {
    PaperStudyOptions options;
    std::vector<Classification> classification;  ///< the 14 settings, in the table's order
    std::vector<GrowthResult> growth;
};

PaperStudy run_paper_study(const PaperStudyOptions& options = {});

}  // namespace ddemap
