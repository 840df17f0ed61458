#include "ddemap/io/paper.hpp"

#include "ddemap/io/csv.hpp"
#include "ddemap/io/figures.hpp"
#include "ddemap/io/files.hpp"
#include "ddemap/io/json.hpp"

namespace ddemap {

namespace {
const char* table_source = "the paper's calibration table (built in)";
}

PaperJob run_paper_job(const std::string& paper_toml, const std::string& paper_source, const std::string& classification_toml,
                       const std::string& classification_source, const PaperStudyOptions& options, const Progress& progress) {
    PaperJob job;
    // units of progress: the study, then every panel of the two charts
    const ChartSpec classes = classification_chart(parse_chart_spec(classification_toml, classification_source), paper_calibration_table(), options.cars);
    job.figure_spec = parse_chart_spec(paper_toml, paper_source);
    const long total = 1 + static_cast<long>(classes.panels.size() + job.figure_spec.panels.size());
    long before = 0, panels = 0;
    ExecutionPolicy charts;
    // a chart reports its grid rows (done of t over all its panels): scaled to its panels
    if (progress) charts.progress = [&](long done, long t) { progress(before + (t > 0 ? done * panels / t : 0), total); };
    job.study = run_paper_study(options);
    if (progress) progress(++before, total);
    panels = static_cast<long>(classes.panels.size());
    job.classification = render_chart(classes, charts);
    before += panels;
    panels = static_cast<long>(job.figure_spec.panels.size());
    job.figure = render_chart(job.figure_spec, charts);
    job.seconds = job.figure.seconds + job.classification.seconds;
    return job;
}

std::vector<std::pair<std::string, std::string>> paper_files(const PaperJob& job, const std::string& prefix) {
    std::vector<std::pair<std::string, std::string>> files;
    const PaperStudy& s = job.study;
    files.emplace_back(prefix + "-classification.csv", classification_csv(s.classification));
    JsonEnvelope e;
    e.command = "classify";
    e.inputs = JsonObject().string("vehicles", table_source).json("ring", json_ring(s.options.cars)).str();
    e.result = classification_json(s.classification, s.options.cars, table_source);
    files.emplace_back(prefix + "-classification.json", envelope_json(e));
    files.emplace_back(prefix + "-classification.svg", job.classification.svg);
    for (auto& f : chart_files(job.figure, prefix)) files.push_back(std::move(f));
    files.emplace_back(prefix + "-growth.csv", growth_csv(s.growth));
    files.emplace_back(prefix + "-growth.svg", growth_svg(s.growth, s.options.lead));
    return files;
}

std::string paper_json(const PaperJob& job) {
    std::vector<std::string> panels;
    for (std::size_t i = 0; i < job.figure.sweeps.size(); ++i) panels.push_back(sweep_json(job.figure.sweeps[i], &job.figure.boundaries[i]));
    return JsonObject()
        .json("panels", json_array(panels))
        .json("classification", classification_json(job.study.classification, job.study.options.cars, table_source))
        .json("growth", growth_json(job.study.growth, job.study.options.lead))
        .number("seconds", job.seconds)
        .str();
}

std::string write_paper(const PaperJob& job, const std::string& prefix) {
    JsonEnvelope e;
    e.command = "paper";
    {
        // trusted as its three parts are: the panels' certificates, the classification's, the platoons' integration
        const std::string chart = chart_message(job.figure), classes = classification_message(job.study.classification),
                          growth = growth_message(job.study.growth);
        e.status = chart_uncertified(job.figure) > 0 ? "uncertified" : "converged";
        for (const GrowthResult& g : job.study.growth)
            if (g.status != Status::Converged && e.status == "converged") e.status = to_string(g.status);
        e.message = "panels: " + chart + "; classification: " + classes + "; growth: " + growth;
    }
    e.inputs = JsonObject().string("out", prefix).json("ring", json_ring(job.study.options.cars)).string("lead", job.study.options.lead)
                   .integer("followers", job.study.options.followers).str();
    e.result = paper_json(job);
    const std::string envelope = envelope_json(e);
    auto files = paper_files(job, prefix);
    files.emplace_back(prefix + ".json", envelope);
    write_files_atomic(files);
    return envelope;
}

}  // namespace ddemap
