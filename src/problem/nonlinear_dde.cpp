#include "ddemap/problem/nonlinear_dde.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace ddemap {

namespace {
std::string known_names(const std::vector<std::string>& names) {
    std::string s;
    for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
    return s.empty() ? "(none)" : s;
}
}  // namespace

NonlinearDDE::NonlinearDDE(std::vector<std::string> names, std::vector<double> values)
    : m_names(std::move(names)), m_values(std::move(values)) {
    if (m_names.size() != m_values.size())
        throw std::invalid_argument(std::to_string(m_names.size()) + " parameter names but " + std::to_string(m_values.size()) +
                                    " values: expected one value per name");
    for (std::size_t i = 0; i < m_names.size(); ++i) {
        for (std::size_t j = 0; j < i; ++j)
            if (m_names[j] == m_names[i]) throw std::invalid_argument("parameter '" + m_names[i] + "' is named twice");
        if (!std::isfinite(m_values[i])) throw std::invalid_argument("parameter '" + m_names[i] + "' is not finite: expected a finite value");
    }
}

ParameterMap NonlinearDDE::parameters() const {
    ParameterMap p;
    for (std::size_t i = 0; i < m_names.size(); ++i) p[m_names[i]] = m_values[i];
    return p;
}

int NonlinearDDE::parameter_index(const std::string& name) const {
    for (std::size_t i = 0; i < m_names.size(); ++i)
        if (m_names[i] == name) return static_cast<int>(i);
    throw std::invalid_argument("parameter '" + name + "' is not a parameter of this system: expected one of " + known_names(m_names));
}

double NonlinearDDE::parameter(const std::string& name) const { return m_values[parameter_index(name)]; }

void NonlinearDDE::set_parameter(const std::string& name, double value) {
    const int i = parameter_index(name);
    if (!std::isfinite(value)) throw std::invalid_argument("parameter '" + name + "': expected a finite value");
    m_values[i] = value;
}

void NonlinearDDE::check_stacked(const Eigen::VectorXd& stacked, const char* what) const {
    const Eigen::Index size = static_cast<Eigen::Index>(dimension()) * (delay_count() + 1);
    if (stacked.size() != size)
        throw std::invalid_argument(std::string(what) + " has " + std::to_string(stacked.size()) + " entries: expected n (m + 1) = " +
                                    std::to_string(size) + " (the state and its " + std::to_string(delay_count()) + " delayed copies)");
    if (!stacked.allFinite()) throw std::invalid_argument(std::string(what) + " has a non-finite entry: expected finite values");
}

Eigen::VectorXd NonlinearDDE::f(const Eigen::VectorXd& stacked) const {
    check_stacked(stacked, "the stacked argument");
    Eigen::VectorXd out(dimension());
    evaluate(stacked.data(), m_values.data(), out.data());
    return out;
}

std::vector<Eigen::MatrixXd> NonlinearDDE::jacobians(const Eigen::VectorXd& stacked) const { return jacobians(stacked, m_values); }

namespace {
void check_values(const std::vector<double>& p, std::size_t count) {
    if (p.size() != count)
        throw std::invalid_argument(std::to_string(p.size()) + " parameter values: expected " + std::to_string(count) + " (one per parameter)");
    for (double v : p)
        if (!std::isfinite(v)) throw std::invalid_argument("a parameter value is not finite: expected finite values");
}
}  // namespace

Eigen::VectorXd NonlinearDDE::f(const Eigen::VectorXd& stacked, const std::vector<double>& p) const {
    check_stacked(stacked, "the stacked argument");
    check_values(p, m_names.size());
    Eigen::VectorXd out(dimension());
    evaluate(stacked.data(), p.data(), out.data());
    return out;
}

std::vector<Eigen::MatrixXd> NonlinearDDE::jacobians(const Eigen::VectorXd& stacked, const std::vector<double>& values) const {
    check_stacked(stacked, "the stacked argument");
    check_values(values, m_names.size());
    const int n = dimension(), m = delay_count();
    const int size = n * (m + 1);
    std::vector<Dual<double>> u(size), p(values.size()), out(n);
    for (int i = 0; i < size; ++i) u[i] = Dual<double>(stacked[i]);
    for (std::size_t j = 0; j < values.size(); ++j) p[j] = Dual<double>(values[j]);
    std::vector<Eigen::MatrixXd> a(m + 1, Eigen::MatrixXd::Zero(n, n));
    for (int c = 0; c < size; ++c) {
        u[c].deriv = 1.0;
        evaluate(u.data(), p.data(), out.data());
        u[c].deriv = 0.0;
        for (int r = 0; r < n; ++r) a[c / n](r, c % n) = out[r].deriv;
    }
    return a;
}

Eigen::VectorXd NonlinearDDE::parameter_derivative(const Eigen::VectorXd& stacked, int j, const std::vector<double>& values) const {
    check_stacked(stacked, "the stacked argument");
    check_values(values, m_names.size());
    if (j < 0 || j >= static_cast<int>(values.size()))
        throw std::invalid_argument("parameter index " + std::to_string(j) + ": expected 0.." + std::to_string(static_cast<int>(values.size()) - 1));
    const int n = dimension(), size = n * (delay_count() + 1);
    std::vector<Dual<double>> u(size), p(values.size()), out(n);
    for (int i = 0; i < size; ++i) u[i] = Dual<double>(stacked[i]);
    for (std::size_t k = 0; k < values.size(); ++k) p[k] = Dual<double>(values[k]);
    p[j].deriv = 1.0;
    evaluate(u.data(), p.data(), out.data());
    Eigen::VectorXd d(n);
    for (int r = 0; r < n; ++r) d[r] = out[r].deriv;
    return d;
}

Eigen::MatrixXd NonlinearDDE::jacobian(const Eigen::VectorXd& stacked, int block) const {
    if (block < 0 || block > delay_count())
        throw std::invalid_argument("block " + std::to_string(block) + ": expected 0 (the current state) to " + std::to_string(delay_count()) +
                                    " (the delays)");
    check_stacked(stacked, "the stacked argument");
    const int n = dimension(), size = n * (delay_count() + 1);
    std::vector<Dual<double>> u(size), p(m_values.size()), out(n);
    for (int i = 0; i < size; ++i) u[i] = Dual<double>(stacked[i]);
    for (std::size_t j = 0; j < m_values.size(); ++j) p[j] = Dual<double>(m_values[j]);
    Eigen::MatrixXd a(n, n);
    for (int c = 0; c < n; ++c) {
        u[block * n + c].deriv = 1.0;
        evaluate(u.data(), p.data(), out.data());
        u[block * n + c].deriv = 0.0;
        for (int r = 0; r < n; ++r) a(r, c) = out[r].deriv;
    }
    return a;
}

Eigen::VectorXd NonlinearDDE::parameter_derivative(const Eigen::VectorXd& stacked, const std::string& name) const {
    const int j = parameter_index(name);
    check_stacked(stacked, "the stacked argument");
    const int n = dimension(), size = n * (delay_count() + 1);
    std::vector<Dual<double>> u(size), p(m_values.size()), out(n);
    for (int i = 0; i < size; ++i) u[i] = Dual<double>(stacked[i]);
    for (std::size_t k = 0; k < m_values.size(); ++k) p[k] = Dual<double>(m_values[k]);
    p[j].deriv = 1.0;
    evaluate(u.data(), p.data(), out.data());
    Eigen::VectorXd d(n);
    for (int r = 0; r < n; ++r) d[r] = out[r].deriv;
    return d;
}

Eigen::VectorXd NonlinearDDE::stack_constant(const Eigen::VectorXd& x) const {
    const int n = dimension();
    if (x.size() != n)
        throw std::invalid_argument("the equilibrium has " + std::to_string(x.size()) + " entries: expected the dimension " + std::to_string(n));
    if (!x.allFinite()) throw std::invalid_argument("the equilibrium has a non-finite entry: expected finite values");
    return x.replicate(delay_count() + 1, 1);
}

std::vector<double> NonlinearDDE::delay_derivatives(const std::vector<double>&, int) const {
    throw std::logic_error("this system gives no derivatives of its delays: expected a system that implements delay_derivatives");
}

void NonlinearDDE::evaluate(const Dual2*, const Dual2*, Dual2*) const {
    throw std::logic_error("this system has no second derivatives: expected a system built on NonlinearDDEOf");
}

void NonlinearDDE::evaluate(const Dual3*, const Dual3*, Dual3*) const {
    throw std::logic_error("this system has no third derivatives: expected a system built on NonlinearDDEOf");
}

void NonlinearDDE::evaluate(const Dual4*, const Dual4*, Dual4*) const {
    throw std::logic_error("this system has no fourth derivatives: expected a system built on NonlinearDDEOf");
}

void NonlinearDDE::evaluate(const Dual5*, const Dual5*, Dual5*) const {
    throw std::logic_error("this system has no fifth derivatives: expected a system built on NonlinearDDEOf");
}

namespace {
void check_direction(const Eigen::VectorXd& d, Eigen::Index size, const char* what) {
    if (d.size() != size)
        throw std::invalid_argument(std::string(what) + " has " + std::to_string(d.size()) + " entries: expected n (m + 1) = " + std::to_string(size));
    if (!d.allFinite()) throw std::invalid_argument(std::string(what) + " has a non-finite entry: expected finite values");
}
}  // namespace

Eigen::VectorXd NonlinearDDE::second_derivative(const Eigen::VectorXd& stacked, const Eigen::VectorXd& a, const Eigen::VectorXd& b) const {
    return second_derivative(stacked, m_values, a, b);
}

Eigen::VectorXd NonlinearDDE::third_derivative(const Eigen::VectorXd& stacked, const Eigen::VectorXd& a, const Eigen::VectorXd& b,
                                               const Eigen::VectorXd& c) const {
    return third_derivative(stacked, m_values, a, b, c);
}

Eigen::VectorXd NonlinearDDE::second_derivative(const Eigen::VectorXd& stacked, const std::vector<double>& pv, const Eigen::VectorXd& a,
                                                const Eigen::VectorXd& b) const {
    check_stacked(stacked, "the stacked argument");
    check_direction(a, stacked.size(), "direction a");
    check_direction(b, stacked.size(), "direction b");
    if (pv.size() != m_values.size()) throw std::invalid_argument("second_derivative: expected " + std::to_string(m_values.size()) + " parameter values");
    std::vector<Dual2> u(stacked.size()), p(pv.size()), out(dimension());
    for (Eigen::Index i = 0; i < stacked.size(); ++i) u[i] = Dual2(Dual<double>(stacked[i], a[i]), Dual<double>(b[i], 0.0));
    for (std::size_t j = 0; j < pv.size(); ++j) p[j] = Dual2(pv[j]);
    evaluate(u.data(), p.data(), out.data());
    Eigen::VectorXd d(dimension());
    for (int r = 0; r < dimension(); ++r) d[r] = out[r].deriv.deriv;
    return d;
}

Eigen::VectorXd NonlinearDDE::third_derivative(const Eigen::VectorXd& stacked, const std::vector<double>& pv, const Eigen::VectorXd& a,
                                               const Eigen::VectorXd& b, const Eigen::VectorXd& c) const {
    check_stacked(stacked, "the stacked argument");
    check_direction(a, stacked.size(), "direction a");
    check_direction(b, stacked.size(), "direction b");
    check_direction(c, stacked.size(), "direction c");
    if (pv.size() != m_values.size()) throw std::invalid_argument("third_derivative: expected " + std::to_string(m_values.size()) + " parameter values");
    using D1 = Dual<double>;
    std::vector<Dual3> u(stacked.size()), p(pv.size()), out(dimension());
    // x + a e1 + b e2 + c e3: value part (x + a e1) + b e2, derivative part (c + 0 e1) + 0 e2
    for (Eigen::Index i = 0; i < stacked.size(); ++i)
        u[i] = Dual3(Dual2(D1(stacked[i], a[i]), D1(b[i], 0.0)), Dual2(D1(c[i], 0.0), D1(0.0, 0.0)));
    for (std::size_t j = 0; j < pv.size(); ++j) p[j] = Dual3(pv[j]);
    evaluate(u.data(), p.data(), out.data());
    Eigen::VectorXd d(dimension());
    for (int r = 0; r < dimension(); ++r) d[r] = out[r].deriv.deriv.deriv;
    return d;
}

LinearDDE linearise(const NonlinearDDE& system, const Eigen::VectorXd& equilibrium) {
    return linearise(system, equilibrium, system.parameter_values());
}

LinearDDE linearise(const NonlinearDDE& system, const Eigen::VectorXd& equilibrium, const std::vector<double>& p) {
    const Eigen::VectorXd u = system.stack_constant(equilibrium);
    const std::vector<double> tau = system.delays(p);
    if (static_cast<int>(tau.size()) != system.delay_count())
        throw std::invalid_argument("the system gives " + std::to_string(tau.size()) + " delays: expected delay_count() = " +
                                    std::to_string(system.delay_count()));
    const std::vector<Eigen::MatrixXd> a = system.jacobians(u, p);
    std::vector<DelayTerm> terms;
    for (std::size_t k = 0; k < tau.size(); ++k) terms.push_back({a[k + 1].cast<cplx>(), tau[k]});
    return LinearDDE(a[0].cast<cplx>(), std::move(terms));
}

double equilibrium_residual(const NonlinearDDE& system, const Eigen::VectorXd& equilibrium) {
    return system.f(system.stack_constant(equilibrium)).cwiseAbs().maxCoeff();
}

}  // namespace ddemap
