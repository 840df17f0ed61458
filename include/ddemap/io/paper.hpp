#pragma once
/// \file paper.hpp
/// The seed paper's main job as one call: run_paper_study (classification and growth) plus
/// the stability charts of the chart specs (maps/paper.toml, maps/classification.toml), and
/// the files it writes.

#include <string>
#include <utility>
#include <vector>

#include "ddemap/io/chart_spec.hpp"
#include "ddemap/study/paper.hpp"

namespace ddemap {

struct PaperJob {
    PaperStudy study;
    ChartSpec figure_spec;          ///< the paper's stability diagrams
    RenderedChart figure;
    RenderedChart classification;   ///< the vehicles on their own charts
    double seconds = 0.0;           ///< chart time
};

/// `paper_toml` and `classification_toml`: the chart specs' text (e.g. maps/paper.toml,
/// maps/classification.toml); `*_source` names them in errors. `progress` (may be empty) counts
/// the study, then every panel of the two charts.
PaperJob run_paper_job(const std::string& paper_toml, const std::string& paper_source, const std::string& classification_toml,
                       const std::string& classification_source, const PaperStudyOptions& options = {},
                       const Progress& progress = {});

/// The files of the job under PREFIX: PREFIX.svg (the paper's diagrams),
/// PREFIX-classification.csv/.json/.svg, PREFIX-panelK.csv and PREFIX-panelK-boundaries.csv
/// for every panel K, PREFIX-growth.csv/.svg. (PREFIX.json, the summary, is the caller's.)
std::vector<std::pair<std::string, std::string>> paper_files(const PaperJob& job, const std::string& prefix);

/// The job's summary (JSON text): per panel the sweep summary, the chart time.
std::string paper_json(const PaperJob& job);

/// The job's files under PREFIX (paper_files) and PREFIX.json, the envelope of `paper` (inputs:
/// out, ring, lead, followers; result: paper_json), written as one set (write_files_atomic);
/// returns the envelope's JSON text, what `ddemap paper --format json` prints.
std::string write_paper(const PaperJob& job, const std::string& prefix);

}  // namespace ddemap
