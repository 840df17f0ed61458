#include "ddemap/analysis/system_roots.hpp"

#include <stdexcept>

namespace ddemap {

void SystemRootOptions::validate() const {
    if (count < 1 || count > 10000) throw std::invalid_argument("count = " + std::to_string(count) + ": expected an integer between 1 and 10000");
    if (degree < 0 || degree == 1 || degree > 200) throw std::invalid_argument("degree = " + std::to_string(degree) + ": expected 0 (automatic) or an integer 2..200");
    if (method == SolverMethod::Product)
        throw std::invalid_argument("solver 'product' goes with fleet rings: expected auto, dense or sparse for a system");
}

SystemRootResult analyse_system(const LinearDDE& dde, const SystemRootOptions& o) {
    o.validate();
    SystemRootResult out;
    out.method_given = o.method;
    const bool sparse = dde.is_real() && !dde.is_ode() &&
                        (o.method == SolverMethod::Sparse || (o.method == SolverMethod::Automatic && dde.dimension() > o.dense_limit));
    if (o.method == SolverMethod::Sparse && !sparse)
        throw std::invalid_argument("solver 'sparse': the sparse path needs real coefficients and at least one delay; expected auto or dense for this system");
    RootResult& r = out.roots;
    if (sparse) {
        SparseDDE s;
        s.a0 = dde.a0().real().sparseView();
        for (const auto& t : dde.delayed()) s.delayed.push_back({Eigen::MatrixXd(t.matrix.real()).sparseView(), t.delay});
        SparseRootOptions so;
        so.count = o.count;
        so.degree = o.degree;
        const SparseRootResult sr = system_rightmost_roots(s, so, SolverMethod::Sparse);
        r.roots = sr.roots;
        r.degree = sr.degree;
        r.status = sr.status;
        r.reason = sr.reason;
        r.strip_floor = sr.strip_floor;
        out.method_used = SolverMethod::Sparse;
    } else {
        RootOptions ro;
        ro.count = o.count;
        r = rightmost_roots(dde, ro);
        out.method_used = SolverMethod::Dense;
    }
    out.spectral_abscissa = r.spectral_abscissa();
    out.stable = r.status == RootStatus::Converged && !r.roots.empty() && out.spectral_abscissa < -marginal_band(r.roots.front().value);
    return out;
}

}  // namespace ddemap
