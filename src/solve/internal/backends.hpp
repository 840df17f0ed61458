#pragma once
// The root backends behind rightmost_roots (roots.hpp); registered in roots.cpp, one per file.

#include <algorithm>
#include <cmath>
#include <string>

#include "ddemap/solve/roots.hpp"

namespace ddemap::detail {

/// One backend: its name, why it does not apply to a problem (empty when it does), and the solver.
struct RootBackend {
    const char* name;
    std::string (*why_not)(const RootProblem& problem, const RootOptions& options);
    RootResult (*solve)(const RootProblem& problem, const RootOptions& options);
    /// The predicted cost (estimate_root_work); `method` is filled by the facade.
    RootWorkEstimate (*estimate)(const RootProblem& problem, const RootOptions& options);
};

std::string dense_why_not(const RootProblem& problem, const RootOptions& options);
RootResult dense_roots(const RootProblem& problem, const RootOptions& options);             // dense_backend.cpp
RootWorkEstimate dense_estimate(const RootProblem& problem, const RootOptions& options);
std::string shift_invert_why_not(const RootProblem& problem, const RootOptions& options);
RootResult shift_invert_roots(const RootProblem& problem, const RootOptions& options);      // shift_invert.cpp
RootWorkEstimate shift_invert_estimate(const RootProblem& problem, const RootOptions& options);
std::string contour_why_not(const RootProblem& problem, const RootOptions& options);
RootResult contour_roots(const RootProblem& problem, const RootOptions& options);           // contour_backend.cpp
RootWorkEstimate contour_estimate(const RootProblem& problem, const RootOptions& options);

inline double scale_of(cplx z) { return std::max(1.0, std::abs(z)); }

}  // namespace ddemap::detail
