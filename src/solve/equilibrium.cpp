#include "ddemap/solve/equilibrium.hpp"

#include <cmath>
#include <stdexcept>

#include <Eigen/Dense>

#include "core/internal/text.hpp"

namespace ddemap {

bool EquilibriumOptions::is_valid(std::string* why) const {
    std::string m;
    if (!newton.is_valid(&m)) {
        if (why) *why = "newton." + m;
        return false;
    }
    if (!(std::isfinite(residual_tolerance) && residual_tolerance > 0.0)) {
        if (why) *why = "residual_tolerance: expected a finite value > 0";
        return false;
    }
    return true;
}

EquilibriumResult find_equilibrium(const NonlinearDDE& system, const Eigen::VectorXd& guess, const EquilibriumOptions& options,
                                   const std::vector<double>& values) {
    std::string why;
    if (!options.is_valid(&why)) throw std::invalid_argument("equilibrium options: " + why);
    const std::vector<double>& p = values.empty() ? system.parameter_values() : values;
    (void)system.stack_constant(guess);  // checks the size and finiteness
    EquilibriumResult r;
    r.x = guess;
    const NewtonSummary s = newton(
        r.x,
        [&](const Eigen::VectorXd& x, Eigen::VectorXd& dx) {
            const Eigen::VectorXd u = system.stack_constant(x);
            const Eigen::VectorXd g = system.f(u, p);
            if (!g.allFinite()) return NewtonStep::Singular;
            if (g.cwiseAbs().maxCoeff() == 0.0) return NewtonStep::Exact;
            const std::vector<Eigen::MatrixXd> a = system.jacobians(u, p);
            Eigen::MatrixXd j = a[0];
            for (std::size_t k = 1; k < a.size(); ++k) j += a[k];
            const Eigen::FullPivLU<Eigen::MatrixXd> lu(j);
            if (!j.allFinite() || !lu.isInvertible()) return NewtonStep::Singular;
            dx = lu.solve(g);
            return NewtonStep::Ok;
        },
        options.newton);
    r.iterations = s.iterations;
    if (r.x.allFinite()) {
        const Eigen::VectorXd g = system.f(system.stack_constant(r.x), p);
        r.residual = g.allFinite() ? g.cwiseAbs().maxCoeff() : std::numeric_limits<double>::infinity();
    }
    r.status = s.status;
    if (converged(s.status) && !(r.residual <= options.residual_tolerance)) r.status = Status::NumericalIssue;
    // (a message never shows "inf" or "nan": the equations may be undefined at the point)
    const std::string residual = std::isfinite(r.residual) ? detail::format_number(r.residual) : std::string("not finite (an equation is infinite or undefined there)");
    if (converged(r.status))
        r.message = "Newton converged in " + std::to_string(r.iterations) + " iterations, residual " + detail::format_number(r.residual);
    else if (s.status == Status::NumericalIssue)
        r.message = "Newton stopped after " + std::to_string(r.iterations) +
                    " iterations: singular or non-finite Jacobian or residual " + residual;
    else if (s.status == Status::MaxIterations)
        r.message = "Newton did not converge in " + std::to_string(r.iterations) + " iterations (residual " + residual + ")";
    else
        r.message = "Newton converged in step but the residual " + residual + " exceeds " + detail::format_number(options.residual_tolerance);
    return r;
}

}  // namespace ddemap
