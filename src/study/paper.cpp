#include "ddemap/study/paper.hpp"

namespace ddemap {

PaperStudy run_paper_study(const PaperStudyOptions& options) {
    PaperStudy s;
    s.options = options;
    s.classification = classify(paper_calibration_table(), options.cars);
    s.growth = disturbance_growth(paper_calibration_table(), LeadProfile::builtin(options.lead), options.followers);
    return s;
}

}  // namespace ddemap
