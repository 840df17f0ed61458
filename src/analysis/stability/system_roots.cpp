#include "ddemap/analysis/stability/system_roots.hpp"

namespace ddemap {

SystemRootResult analyse_system(const LinearDDE& dde, const RootOptions& options) {
    SystemRootResult out;
    out.roots = rightmost_roots(dde, options);
    const RootResult& r = out.roots;
    out.spectral_abscissa = r.spectral_abscissa();
    out.stable = r.status == Status::Converged && !r.roots.empty() &&
                 out.spectral_abscissa < -marginal_band(r.roots.front().value);
    if (r.status != Status::Converged || r.roots.empty()) {
        out.verdict = Verdict::Undecided;
    } else {
        const double band = marginal_band(r.roots.front().value);
        out.verdict = out.spectral_abscissa > band ? Verdict::Unstable : out.stable ? Verdict::Stable : Verdict::Marginal;
    }
    return out;
}

}  // namespace ddemap
