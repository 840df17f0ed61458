// The covariance travels from `calibrate`'s CSV to `classify`'s reader unchanged, and the
// classification outputs carry the probabilities only when a covariance was given.
#include <doctest/doctest.h>

#include <string>

#include "ddemap/io/csv.hpp"
#include "ddemap/io/figures.hpp"
#include "ddemap/io/json.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;

TEST_CASE("calibration CSV covariance columns read back exactly by the vehicles reader") {
    CalibrationResult r;
    r.parameters = {{"k1", 0.1}, {"k2", 0.4}, {"th", 1.2}, {"tau", 0.5}, {"eta", 7.0}};
    Eigen::Matrix<double, 5, 5> m = Eigen::Matrix<double, 5, 5>::Random();
    const Eigen::Matrix<double, 5, 5> c = m * m.transpose() / 3.0;  // positive semidefinite, digits that need 17 places
    r.covariance = 0.5 * (c + c.transpose());                           // exactly symmetric
    for (int i = 0; i < 5; ++i) r.estimates[static_cast<std::size_t>(i)].standard_error = std::sqrt(r.covariance(i, i));
    r.status = "converged";
    const std::string csv = calibration_csv({"car"}, {r}, CalibrationOptions{});
    const auto v = read_vehicles_csv(csv, "fits.csv");
    REQUIRE(v.size() == 1);
    CHECK(v[0].has_covariance);
    CHECK(v[0].covariance == r.covariance);
    CHECK(v[0].parameters.at("th") == 1.2);
    // a parameter the trace does not determine (infinite standard error): no covariance written
    r.estimates[3].standard_error = std::numeric_limits<double>::infinity();
    const auto w = read_vehicles_csv(calibration_csv({"car"}, {r}, CalibrationOptions{}), "fits.csv");
    CHECK_FALSE(w[0].has_covariance);
    // no covariance columns: a plain vehicle table
    CHECK_FALSE(read_vehicles_csv("name,k1,k2,th,tau\nA,0.1,0.4,1.2,0.5\n", "plain.csv")[0].has_covariance);
    // some of the columns, a partly filled row, a negative variance: errors naming the problem
    CHECK_THROWS_WITH_AS(read_vehicles_csv("name,k1,k2,th,tau,cov_k1_k1\nA,0.1,0.4,1.2,0.5,1\n", "p.csv"),
                         doctest::Contains("1 of the 15 covariance columns"), std::invalid_argument);
    std::string header = "name,k1,k2,th,tau", row = "A,0.1,0.4,1.2,0.5";
    for (const auto& c : covariance_column_names()) {
        header += "," + c;
        row += c == "cov_k2_k2" ? ",-1" : ",0";
    }
    CHECK_THROWS_WITH_AS(read_vehicles_csv(header + "\n" + row + "\n", "n.csv"), doctest::Contains("cov_k2_k2"), std::invalid_argument);
    std::string partial = "A,0.1,0.4,1.2,0.5,1";
    for (int i = 1; i < 15; ++i) partial += ",";
    CHECK_THROWS_WITH_AS(read_vehicles_csv(header + "\n" + partial + "\n", "q.csv"), doctest::Contains("1 of the 15"), std::invalid_argument);
}

TEST_CASE("calibration CSV carries the fit's bounds and classify samples within them, not within the default bounds") {
    CalibrationResult r;
    r.parameters = {{"k1", 0.98}, {"k2", 0.4}, {"th", 1.2}, {"tau", 0.5}, {"eta", 7.0}};
    r.covariance = Eigen::Matrix<double, 5, 5>::Zero();
    r.covariance(0, 0) = 0.05 * 0.05;  // k1 = 0.98 +- 0.05: half its mass above the default bound 1
    r.covariance(3, 3) = 0.1 * 0.1;
    for (int i = 0; i < 5; ++i) r.estimates[static_cast<std::size_t>(i)].standard_error = std::sqrt(r.covariance(i, i));
    r.status = "converged";
    CalibrationOptions o;
    o.set_bounds("k1", 0.9, 1.5);
    o.set_bounds("tau", 0.45, 0.55);
    o.set_bounds("eta", 2.0, 12.0);
    const std::string csv = calibration_csv({"car"}, {r}, o);
    CHECK(csv.substr(0, csv.find('\n')).find(",cov_eta_eta,lo_k1_per_s2,hi_k1_per_s2,lo_k2_per_s,hi_k2_per_s,lo_th_s,hi_th_s,lo_tau_s,hi_tau_s,lo_eta_m,hi_eta_m") !=
          std::string::npos);
    const auto v = read_vehicles_csv(csv, "fits.csv");
    REQUIRE(v.size() == 1);
    REQUIRE(v[0].bounds.size() == 5);
    for (const auto& name : calibration_parameter_names()) {
        const BoundedParameter* b = find_bound(v[0].bounds, name);
        REQUIRE(b != nullptr);
        CHECK(b->lower == o.bound(name).lower);
        CHECK(b->upper == o.bound(name).upper);
    }
    // the CLI's domain: calibrate's default bounds of k1, k2, th, tau
    UncertaintyOptions uo;
    for (const auto& b : paper_calibration_bounds())
        if (b.name != "eta") uo.domain.push_back(b);
    uo.samples = 200;
    uo.ring_samples = 0;
    const auto rows = classify(v, 22, uo);
    REQUIRE(rows[0].has_uncertainty);
    const VerdictUncertainty& u = rows[0].uncertainty;
    CHECK(u.domain_from_fit);
    CHECK(u.samples == 200);
    int above_default = 0;
    for (const auto& s : u.verdicts) {
        CHECK(s.parameters.at("k1") >= 0.9);
        CHECK(s.parameters.at("k1") <= 1.5);
        CHECK(s.parameters.at("tau") >= 0.45);
        CHECK(s.parameters.at("tau") <= 0.55);
        above_default += s.parameters.at("k1") > 1.0 ? 1 : 0;
    }
    CHECK(above_default > 50);  // not truncated at the default bound k1 <= 1 (about a third of 200 expected)
    CHECK(classification_json(rows, 22, "x").find("\"bounds_source\":\"file\"") != std::string::npos);
    // a file without bounds: the default domain, said so
    std::vector<CalibratedVehicle> w = read_vehicles_csv("name,k1,k2,th,tau\ncar,0.98,0.4,1.2,0.5\n", "plain.csv");
    CHECK(w[0].bounds.empty());
    w[0].covariance = v[0].covariance;
    w[0].has_covariance = true;
    const auto dflt = classify(w, 22, uo);
    CHECK_FALSE(dflt[0].uncertainty.domain_from_fit);
    for (const auto& s : dflt[0].uncertainty.verdicts) CHECK(s.parameters.at("k1") <= 1.0);
    CHECK(classification_json(dflt, 22, "x").find("\"bounds_source\":\"default\"") != std::string::npos);
    // one bound of a pair, a reversed pair, a half-filled pair: errors naming the column
    CHECK_THROWS_WITH_AS(read_vehicles_csv("name,k1,k2,th,tau,lo_k1\nA,0.1,0.4,1.2,0.5,0\n", "b.csv"), doctest::Contains("lo_k1 without hi_k1"),
                         std::invalid_argument);
    CHECK_THROWS_WITH_AS(read_vehicles_csv("name,k1,k2,th,tau,lo_k1,hi_k1\nA,0.1,0.4,1.2,0.5,2,1\n", "b.csv"),
                         doctest::Contains("expected lower <= upper"), std::invalid_argument);
    CHECK_THROWS_WITH_AS(read_vehicles_csv("name,k1,k2,th,tau,lo_k1,hi_k1\nA,0.1,0.4,1.2,0.5,0,\n", "b.csv"),
                         doctest::Contains("both filled or both empty"), std::invalid_argument);
}

TEST_CASE("classification outputs: probabilities and intervals only for vehicles with a covariance") {
    CalibratedVehicle a;
    a.name = "a";
    a.parameters = {{"k1", 0.052}, {"k2", 0.338}, {"th", 0.819}, {"tau", 0.948}, {"eta", 8.0}};
    a.covariance = 1e-8 * Eigen::Matrix<double, 5, 5>::Identity();
    a.has_covariance = true;
    CalibratedVehicle b = a;
    b.name = "b";
    b.has_covariance = false;
    UncertaintyOptions o;
    o.samples = 50;
    o.ring_samples = 3;
    const auto rows = classify({a, b}, 22, o);
    const std::string json = classification_json(rows, 22, "x");
    CHECK(json.find("\"p_string_unstable\":1") != std::string::npos);
    CHECK(json.find("\"margin_intervals\"") != std::string::npos);
    const std::string csv = classification_csv(rows);
    CHECK(csv.find(",p_string_unstable,") != std::string::npos);
    // without any covariance the outputs are as before (no new columns or keys)
    const auto plain = classify({b}, 22, o);
    CHECK(classification_csv(plain).find("p_string_unstable") == std::string::npos);
    CHECK(classification_json(plain, 22, "x").find("p_string_unstable") == std::string::npos);
}

TEST_CASE("classification figure: window fitted to the user's vehicles, their ellipses, a legend of what is shown") {
    const ChartSpec base = parse_chart_spec(
        "title = \"t\"\nmodel = \"ovrv\"\nring = 22\ncolumns = 2\nvehicles = \"paper\"\n[x]\nname = \"k1\"\nlo = 0.002\nhi = 0.1\ncount = 9\n"
        "[y]\nname = \"k2\"\nlo = 0.05\nhi = 0.8\ncount = 9\n",
        "base.toml");
    CalibratedVehicle a;
    a.name = "mine";
    a.parameters = {{"k1", 0.3}, {"k2", 0.6}, {"th", 1.5}, {"tau", 0.3}, {"eta", 8.0}};
    a.covariance = Eigen::Matrix<double, 5, 5>::Zero();
    a.covariance(0, 0) = 1e-3;
    a.covariance(1, 1) = 4e-3;
    a.covariance(0, 1) = a.covariance(1, 0) = 1e-3;
    a.has_covariance = true;
    CalibratedVehicle b = a;
    b.name = "other";
    b.parameters["k1"] = 0.5;
    b.has_covariance = false;
    const ChartSpec spec = classification_chart(base, {a, b}, 22, "fits.csv");
    CHECK(spec.title.find("fits.csv") != std::string::npos);
    // both vehicles and a's ellipse extent sqrt(5.991 C_ii) lie inside the fitted window
    const double ex = std::sqrt(5.991464547107979 * 1e-3), ey = std::sqrt(5.991464547107979 * 4e-3);
    CHECK(spec.x.lo <= 0.3 - ex);
    CHECK(spec.x.hi >= 0.5);
    CHECK(spec.y.lo <= 0.6 - ey);
    CHECK(spec.y.hi >= 0.6 + ey);
    CHECK(spec.x.lo > 0.0);
    // one panel per distinct (tau, th): both cars in it
    REQUIRE(spec.panels.size() == 1);
    REQUIRE(spec.panels[0].markers.size() == 2);
    CHECK(spec.panels[0].markers[0].has_ellipse);
    CHECK_FALSE(spec.panels[0].markers[1].has_ellipse);
    CalibratedVehicle c = b;
    c.name = "third";
    c.parameters["th"] = 2.0;
    CHECK(classification_chart(base, {a, b, c}, 22, "fits.csv").panels.size() == 2);
    const std::string svg = render_chart(spec).svg;
    CHECK(svg.find("95 % confidence ellipse") != std::string::npos);
    CHECK(svg.find("(outside)") == std::string::npos);
    // the legend names only region classes and curves that the panels show: these settings are
    // plant stable everywhere in the window (th = 1.5 s, tau = 0.3 s, k1, k2 > 0)
    const RenderedChart r = render_chart(spec);
    bool plant_unstable = false;
    for (const auto& sw : r.sweeps)
        for (const auto& p : sw.points) plant_unstable = plant_unstable || !p.plant_stable;
    CHECK((svg.find(">plant unstable<") != std::string::npos) == plant_unstable);
    CHECK(svg.find("k\u2081 [1/s\u00b2]") != std::string::npos);
    // long names and a long title: the figure widens, the names go to a numbered key
    CalibratedVehicle d = a, e = b;
    d.name = std::string(60, 'D');
    e.name = "E with a name that is long enough not to fit beside its marker in a panel of 260 px";
    const ChartSpec long_spec = classification_chart(base, {d, e}, 22, std::string(150, 'f') + ".csv");
    const std::string long_svg = render_chart(long_spec).svg;
    const auto width_at = long_svg.find("width=\"");
    REQUIRE(width_at != std::string::npos);
    CHECK(std::stod(long_svg.substr(width_at + 7)) >= 0.62 * 12 * long_spec.title.size());  // the title at 12 px or more fits
    CHECK(long_svg.find(">1</tspan>  " + d.name + "<") != std::string::npos);                   // the key
    CHECK(long_svg.find(">2</tspan>  " + e.name + "<") != std::string::npos);
    // the paper's table (no source): the base window and title
    const ChartSpec paper = classification_chart(base, {b}, 22);
    CHECK(paper.x.lo == base.x.lo);
    CHECK(paper.title == base.title);
}

TEST_CASE("chart markers outside the window are flagged at its edge, not drawn outside the panel") {
    const ChartSpec spec = parse_chart_spec(
        "model = \"ovrv\"\nring = 22\n[x]\nname = \"k1\"\nlo = 0.05\nhi = 0.5\ncount = 7\n"
        "[y]\nname = \"k2\"\nlo = 0.05\nhi = 0.8\ncount = 7\n[[panel]]\nth = 1.5\ntau = 0.3\n[[panel.marker]]\nk1 = 0.9\nk2 = 0.3\nlabel = \"far\"\n"
        "[[panel.marker]]\nk1 = 0.2\nk2 = 0.3\nlabel = \"near\"\n",
        "outside.toml");
    const std::string svg = render_chart(spec).svg;
    CHECK(svg.find("far (outside)") != std::string::npos);
    CHECK(svg.find("near (outside)") == std::string::npos);
    CHECK(svg.find("outside the window") != std::string::npos);  // and the legend says what the mark means
}
