#pragma once
/// \file ring_stability.hpp
/// Rightmost roots and the stability verdict of a ring of N identical cars, mode by mode
/// (traffic/ring.hpp); N = infinity over every wave number theta.

#include <functional>
#include <string>
#include <vector>

#include "ddemap/core/execution.hpp"
#include "ddemap/solve/roots.hpp"
#include "ddemap/traffic/model.hpp"
#include "ddemap/traffic/ring.hpp"

namespace ddemap {

struct RingOptions {
    RootOptions roots;      ///< per-mode options; roots.count is the number of roots reported
    int theta_grid = 64;    ///< N = infinity: uniform wave numbers in (0, pi] before refinement
    /// N finite: after every mode of the first pass over the N/2 + 1 modes (modes done, modes).
    /// N = infinity: after every wave number of the scan solved (done, at most theta_grid + 13 +
    /// 43: the grid, the golden section and the abscissa's wave number; the bound becomes the
    /// exact count once the golden section has ended); the search for roots.count roots at the
    /// abscissa's wave number, whose length is not known, reports its steps through
    /// roots.progress instead (the scan's searches do not call it). It may throw to stop, and
    /// the exception reaches the caller; so does a ddemap::Cancelled thrown by roots.progress
    /// (which is also called within a long dense degree of that search: solve/roots.hpp).
    Progress progress;
    /// N finite: called once before the modes are solved, with their number (N/2 + 1) and
    /// estimate_root_work's prediction for the first nonzero mode's root search (the modes are
    /// alike in size); it may throw (a size guard refusing the work; the exception reaches the
    /// caller). May be empty.
    std::function<void(long modes, const RootWorkEstimate& one)> before;
    void validate() const;
};

struct RingRoot {
    Root root;
    int mode = 0;         ///< m of zeta = exp(-2 pi i m / N); -1 for N = infinity
    double theta = 0.0;   ///< wave number 2 pi m / N (N = infinity: the theta of this root)
};

struct RingResult {
    int cars = 0;                    ///< N; 0 stands for infinity
    std::vector<RingRoot> roots;     ///< the rightmost roots over all modes, rightmost first
    double spectral_abscissa = 0.0;  ///< max Re over all roots, trivial zero excluded
    int abscissa_mode = 0;           ///< mode where it is reached (-1 for N = infinity)
    double abscissa_theta = 0.0;     ///< its wave number
    bool abscissa_is_limit = false;  ///< N = infinity: the sup 0 is only approached as theta -> 0
    int unstable_roots = 0;          ///< roots with Re > marginal band, all modes (-1 for N = infinity)
    int marginal_roots = 0;          ///< roots within the marginal band of the axis
    bool stable = false;             ///< every root (trivial one excluded) has Re < -marginal band
    /// Stable, Marginal (no root right of the band, some within it), Unstable, or Undecided
    /// when status is not Converged (then `stable` is false and the counts are not a verdict).
    Verdict verdict = Verdict::Undecided;
    bool trivial_branch_stable = false;  ///< N = infinity: the branch through the trivial root bends left
    int degree = 0;                  ///< the largest collocation degree used over the modes
    int modes_solved = 0;            ///< mode (or wave-number) problems solved
    Status status = Status::Converged;  ///< worst status over the modes
    std::string reason;              ///< how the degree was chosen and trusted
};

/// Rightmost roots and the stability verdict of the ring (cars >= 2, or 0 for infinity).
RingResult analyse_ring(const Linearisation& lin, int cars, const RingOptions& options = {});

}  // namespace ddemap
