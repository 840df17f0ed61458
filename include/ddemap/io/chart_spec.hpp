#pragma once
/// \file chart_spec.hpp
/// Chart specifications: a small TOML format (see maps/*.toml) naming the model, the ring, the
/// two swept parameters, fixed parameters common to all panels, and one [[panel]] per panel
/// with its own fixed parameters and optional [[panel.marker]] entries; or
/// `vehicles = "paper"` (the built-in calibration table) or `vehicles = "CARS"` (a car list,
/// io/cars.hpp: "mycars.csv", "fits.json", "A_min,mycars.csv:Sedan", ...; files found beside
/// the spec) for one panel per distinct (tau, th), every car of it marked at its (k1, k2).

#include <string>
#include <utility>
#include <vector>

#include "ddemap/core/execution.hpp"
#include "ddemap/io/svg.hpp"
#include "ddemap/traffic/model.hpp"
#include "ddemap/traffic/vehicles.hpp"
#include "ddemap/study/boundary.hpp"
#include "ddemap/study/sweep.hpp"
#include "ddemap/analysis/stability/classify.hpp"
#include "ddemap/analysis/design/design.hpp"

namespace ddemap {

struct PanelSpec {
    std::string title;        ///< empty: made from the panel's fixed parameters
    ParameterMap parameters;  ///< panel-specific fixed parameters
    std::vector<ChartMarker> markers;
};

struct ChartSpec {
    std::string title;
    std::string model = "ovrv";
    int cars = 22;            ///< 0 = infinity
    ParameterMap fixed;
    Axis x, y;
    int columns = 3;
    double panel_width = 260, panel_height = 220;
    bool boundaries = true;
    /// key peak = true: every panel also decides peak (L-infinity) string stability (SweepSpec::peak)
    bool peak = false;
    /// ring Hopf curves of the boundaries (key ring_curves = "all" | "envelope" | "auto",
    /// study/boundary.hpp RingCurves)
    RingCurves ring_curves = RingCurves::Auto;
    std::vector<PanelSpec> panels;
};

/// Parses a chart spec; std::invalid_argument naming `source`, the line and the key on error.
ChartSpec parse_chart_spec(const std::string& text, const std::string& source);

/// The sweep of one panel: the chart's model, window and ring with the panel's parameters.
SweepSpec panel_sweep(const ChartSpec& spec, std::size_t panel);

/// Panels for a list of cars (of the ovrv law): one per distinct (tau, th), every car of that
/// (tau, th) marked in it at its (k1, k2), with its 95 % ellipse where it has a covariance.
std::vector<PanelSpec> vehicle_panels(const std::vector<CalibratedVehicle>& vehicles);

/// The sweeps and boundaries of every panel, and the SVG.
struct RenderedChart {
    std::vector<SweepSpec> specs;
    std::vector<SweepResult> sweeps;
    std::vector<BoundarySet> boundaries;
    std::string svg;
    double seconds = 0.0;
};

/// Panels run one after the other (each sweep in parallel under `policy`); the policy's
/// progress counts the grid rows swept, over all panels (rows done, rows of every panel).
RenderedChart render_chart(const ChartSpec& spec, const ExecutionPolicy& policy = {});

/// The files of a rendered chart: PREFIX.svg, and for panel K its grid PREFIX-panelK.csv (as
/// `sweep` writes it) and its boundary curves PREFIX-panelK-boundaries.csv.
std::vector<std::pair<std::string, std::string>> chart_files(const RenderedChart& chart, const std::string& prefix);

/// The figure of `sweep --out`: one panel, the sweep's regions, its boundaries (optional) and
/// the markers, titled by sweep_chart_title.
std::string sweep_chart_svg(const SweepSpec& spec, const SweepResult& sweep, const BoundarySet* boundaries, const std::vector<ChartMarker>& markers);

/// A sweep chart's title: "MODEL, p = v unit, ..., N = n" (each fixed parameter with its symbol,
/// its value to 4 digits and its unit).
std::string sweep_chart_title(const SweepSpec& spec);

/// The cars as markers of a sweep's chart: each at its values of the two swept parameters, with
/// the (x, y) block of a fit's covariance as its 95 % ellipse. std::invalid_argument (naming
/// the car) for a car of another model or without a value of an axis. A car whose other
/// parameters differ from the chart's fixed ones (eta excepted on OVRV's charts, where it moves
/// no boundary) adds a line to `notes`: its marker shows its x and y on a chart not its own.
std::vector<ChartMarker> car_markers(const std::vector<CalibratedVehicle>& cars, const SweepSpec& spec,
                                     std::vector<std::string>* notes = nullptr);

/// A design on its (k1, k2) stability charts (`design --out`): the car's gains ("CAR") and the
/// designed ones ("CAR, designed") as markers on the chart of the car's other parameters, with
/// the car's 95 % confidence ellipse of (k1, k2) when `covariance` (order k1, k2, th, tau, eta)
/// is given; when the design changed other parameters too (th, ...), a second panel shows the
/// chart at the designed values with both markers. The window holds both points (and the
/// ellipse's extent) with a quarter of their span around them; ring of `cars` cars (0 = inf).
/// Empty when the law has no k1 and k2.
std::string design_chart_svg(const DesignResult& design, const std::string& car_name, int cars, const Eigen::Matrix<double, 5, 5>* covariance,
                             const ExecutionPolicy& policy = {});

/// The number of grid points of all panels without a certificate (SweepResult::uncertified summed).
long chart_uncertified(const RenderedChart& chart);
/// Why the chart is trusted, or which panel is not: "every grid point of the N panels certified
/// ..." (as sweep_message says it), else "panel K: M points have no certificate ...".
std::string chart_message(const RenderedChart& chart);

}  // namespace ddemap
