#pragma once
/// \file expression_system.hpp
/// A nonlinear DDE whose right-hand side is text (problem/expression.hpp):
///     x_i'(t) = f_i(x(t), x(t - tau_1(p)), ..., x(t - tau_m(p)); p),   i = 1..n,
/// with one delay slot per distinct delay expression tau_k(p) met in the equations. Derivatives of
/// every order (double, Dual, Dual<Dual>, three levels) come from the one compiled program.

#include <string>
#include <vector>

#include "ddemap/problem/expression.hpp"
#include "ddemap/problem/nonlinear_dde.hpp"

namespace ddemap {

class ExpressionSystem final : public NonlinearDDEOf<ExpressionSystem> {
public:
    /// Variables x_1..x_n, parameters with their values, one equation per variable.
    /// std::invalid_argument for a bad name (a function's, t, repeated, or not an identifier), a
    /// parse error (equation and character position) or a non-finite value.
    ExpressionSystem(std::vector<std::string> variables, std::vector<std::string> parameters, std::vector<double> values,
                     const std::vector<std::string>& equations);

    int dimension() const override { return static_cast<int>(m_variables.size()); }
    int delay_count() const override { return static_cast<int>(m_parsed.delays.size()); }
    /// tau_k(p) for k = 1..m (std::invalid_argument when one is negative or not finite).
    std::vector<double> delays(const std::vector<double>& p) const override;
    using NonlinearDDE::delays;
    /// d tau_k / d p_j: each delay expression evaluated in dual numbers seeded at p_j.
    std::vector<double> delay_derivatives(const std::vector<double>& p, int j) const override;
    bool has_delay_derivatives() const override { return true; }

    const std::vector<std::string>& variables() const { return m_variables; }
    const std::vector<std::string>& equations() const { return m_texts; }
    /// The source text of delay k (0-based).
    const std::string& delay_text(int k) const { return m_parsed.delay_texts.at(static_cast<std::size_t>(k)); }

    template <class T>
    void rhs(const T* u, const T* p, T* out) const {
        for (std::size_t i = 0; i < m_parsed.equations.size(); ++i) out[i] = m_parsed.equations[i].template evaluate<T>(u, p);
    }

private:
    std::vector<std::string> m_variables;
    std::vector<std::string> m_texts;
    ParsedEquations m_parsed;
};

}  // namespace ddemap
