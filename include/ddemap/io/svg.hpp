#pragma once
/// \file chart.hpp
/// Stability charts as SVG: shaded regions from a sweep (plant unstable, ring unstable, string
/// unstable, string stable), boundary curves from the continuation drawn over them, axes with
/// ticks and labels in units, a legend, titles and optional labelled markers; one or more
/// panels (small multiples). The writer only formats what it is given.

#include <stdexcept>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "ddemap/io/files.hpp"  // WriteError, write_files_atomic (the writers of the figures)
#include "ddemap/study/boundary.hpp"
#include "ddemap/study/sweep.hpp"

namespace ddemap {

struct ChartMarker {
    double x = 0.0, y = 0.0;
    std::string label;
    /// Covariance of (x, y): drawn as the 95 % confidence ellipse (x, y) + {d : d^T C^-1 d <= 5.991}.
    bool has_ellipse = false;
    double cov_xx = 0.0, cov_xy = 0.0, cov_yy = 0.0;
};

struct ChartPanel {
    std::string title;                  ///< e.g. "tau = 0.5 s, th = 1.5 s"
    const SweepResult* sweep = nullptr;  ///< regions (required)
    const BoundarySet* boundaries = nullptr;  ///< curves (optional)
    std::vector<ChartMarker> markers;
    /// a minimiser's path (x, y) drawn as a thin polyline with a dot per iterate (e.g. design's)
    std::vector<std::pair<double, double>> path;
};

struct ChartOptions {
    std::string title;
    int columns = 3;
    double panel_width = 300.0;   ///< plot area, px
    double panel_height = 250.0;
};

/// Region class of a sweep point: 0 plant unstable, 1 ring unstable, 2 string unstable,
/// 3 string stable.
int region_class(const SweepPoint& p);

/// The symbol of a model parameter in figures: k1 -> k₁, k2 -> k₂, tau -> τ, th -> tₕ, eta -> η, ...
/// (other names unchanged).
std::string parameter_symbol(const std::string& name);
/// A unit in figures: 1/s^2 -> 1/s².
std::string unit_text(const std::string& unit);
/// "k₁ [1/s²]" for a model parameter (with the unit from the model's parameter table).
std::string axis_label(const std::string& model, const std::string& parameter);

std::string render_chart_svg(const std::vector<ChartPanel>& panels, const ChartOptions& options);

/// Line plots (simulation traces, disturbance growth, calibration fits).
struct PlotSeries {
    std::string name;
    std::vector<double> x, y;
    std::string colour;  ///< empty: from the palette
    bool dashed = false;
};

struct PlotMarker {
    double x = 0.0, y = 0.0;
    std::string colour = "#000000";
    std::string label;  ///< optional text next to the cross
};

/// A filled region under the series (e.g. a bistable region): polygons of one colour, one legend entry.
struct PlotFill {
    std::string name;
    std::vector<std::vector<std::pair<double, double>>> polygons;  ///< (x, y) corners of each
    std::string colour;
    double opacity = 0.45;
};

struct PlotPanel {
    std::string title, x_label, y_label;
    std::vector<PlotSeries> series;
    std::vector<PlotMarker> markers;  ///< drawn as crosses
    /// The y axis does not extend below this when no data lie below it (a gap is never
    /// negative: the padding around the data stops at 0 instead of showing -10 m).
    double y_floor = -std::numeric_limits<double>::infinity();
    /// The y axis starts at y_floor itself when no data lie below it (a speed axis from 0 m/s,
    /// so that a drop is seen against the whole speed).
    bool y_from_floor = false;
    std::vector<PlotFill> fills{};  ///< drawn first, under the series, clipped to the plot area
    /// a fixed window [x_min, x_max] x [y_min, y_max] (all four finite: no padding, ticks inside it)
    double x_min = std::numeric_limits<double>::quiet_NaN(), x_max = std::numeric_limits<double>::quiet_NaN();
    double y_min = std::numeric_limits<double>::quiet_NaN(), y_max = std::numeric_limits<double>::quiet_NaN();
};

struct PlotOptions {
    std::string title;
    int columns = 2;
    double panel_width = 420.0, panel_height = 280.0;
    bool legend = true;
    std::string note;  ///< one line under the legend (e.g. what the markers mean)
};

std::string render_line_plots_svg(const std::vector<PlotPanel>& panels, const PlotOptions& options);

/// The i-th colour of the line plots' palette (14 colours, repeating): the colour a series with
/// an empty colour gets at position i.
std::string plot_colour(std::size_t i);

}  // namespace ddemap
