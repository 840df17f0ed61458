#pragma once
// Helpers shared by the benchmark programs.
#include <algorithm>
#include <stdexcept>
#include <vector>

namespace ddemap::bench {

/// The median of the samples (the mean of the two middle ones for an even count); figures are
/// noisy, so the benchmarks quote medians. std::invalid_argument for no samples.
inline double median(std::vector<double> v) {
    if (v.empty()) throw std::invalid_argument("median of no samples");
    std::sort(v.begin(), v.end());
    const std::size_t k = v.size() / 2;
    return v.size() % 2 ? v[k] : 0.5 * (v[k - 1] + v[k]);
}

}  // namespace ddemap::bench
