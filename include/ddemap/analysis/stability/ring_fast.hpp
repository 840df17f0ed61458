#pragma once
/// \file ring_fast.hpp
/// The ring of identical cars for roots and string (command line and Python): the verdict, counts and spectral abscissa from
/// one winding pass (analysis/ring_winding.hpp, cost independent of N) where the car reacts only to
/// the car ahead, the per-mode path (analysis/ring_stability.hpp) otherwise or where the winding
/// pass is undecided on a ring of at most kWindingFallbackCars cars.
#include <string>

#include "ddemap/analysis/stability/ring_stability.hpp"
#include "ddemap/analysis/stability/ring_winding.hpp"

namespace ddemap {

/// The largest ring the per-mode path takes (0.3 ms per mode) and the one the winding path takes.
constexpr int kModesMaxCars = 1000000;
constexpr int kWindingMaxCars = 1000000000;

/// "winding" or "modes" for this car law and the method asked ("auto", "winding" or "modes");
/// std::invalid_argument for another name, or for "winding" when the law uses more than the car ahead.
std::string resolve_ring_method(const std::string& given, const Linearisation& lin);

struct FastRing {
    RingResult ring;            ///< verdict, counts, abscissa; roots: the listed ones
    std::string method_used;    ///< "winding" or "modes" (where the verdict came from)
    std::string listed_by;      ///< "modes" (per-mode path), "newton" (neighbouring modes of the abscissa mode) or "none"
    bool winding_ran = false;
    RingWindingResult winding;  ///< when winding_ran
    bool fell_back = false;     ///< the winding pass was undecided and the per-mode path decided
};

/// The ring's verdict and, when `count` > 0, its listed roots. `method` is "winding" or "modes";
/// the per-mode path needs cars <= kModesMaxCars (checked by the caller). `progress`: the per-mode
/// path's (RingOptions::progress; it may throw to stop); the winding pass does not report.
/// `search`: N = infinity, the steps of the search for the `count` roots at the abscissa's
/// wave number (RingOptions::roots.progress). `before`: the per-mode path's size guard
/// (RingOptions::before), called only when that path runs.
FastRing analyse_ring_fast(const Linearisation& lin, int cars, const std::string& method, int count, const Progress& progress = {},
                           const BranchProgress& search = {}, const std::function<void(long, const RootWorkEstimate&)>& before = {});

}  // namespace ddemap
