#include "ddemap/problem/expression_system.hpp"

#include <cmath>
#include <stdexcept>

#include "core/internal/text.hpp"

namespace ddemap {

namespace {

std::vector<std::string> checked(std::vector<std::string> names, const std::vector<std::string>& others, const std::string& what) {
    for (std::size_t i = 0; i < names.size(); ++i) {
        ExpressionNames::check_name(names[i], what);
        for (std::size_t j = 0; j < i; ++j)
            if (names[j] == names[i]) throw std::invalid_argument(what + " " + detail::quoted(names[i]) + " is named twice: expected distinct names");
        for (const auto& o : others)
            if (o == names[i]) throw std::invalid_argument(what + " " + detail::quoted(names[i]) + " is also a variable: expected distinct names");
    }
    return names;
}

}  // namespace

ExpressionSystem::ExpressionSystem(std::vector<std::string> variables, std::vector<std::string> parameters, std::vector<double> values,
                                   const std::vector<std::string>& equations)
    : NonlinearDDEOf(checked(std::move(parameters), variables, "parameter"), std::move(values)),
      m_variables(checked(std::move(variables), {}, "variable")),
      m_texts(equations) {
    if (m_variables.empty()) throw std::invalid_argument("the system has no variables: expected at least one");
    ExpressionNames names{m_variables, parameter_names()};
    m_parsed = parse_equations(equations, names);
    (void)delays();  // the delays at the given values must be usable
}

std::vector<double> ExpressionSystem::delays(const std::vector<double>& p) const {
    if (p.size() != parameter_names().size())
        throw std::invalid_argument(std::to_string(p.size()) + " parameter values: expected " + std::to_string(parameter_names().size()));
    std::vector<double> d;
    for (std::size_t k = 0; k < m_parsed.delays.size(); ++k) {
        const double tau = m_parsed.delays[k].evaluate<double>(nullptr, p.data());
        if (!(std::isfinite(tau) && tau >= 0.0))
            throw std::invalid_argument("the delay " + detail::escaped(m_parsed.delay_texts[k], 80) + " is " + (std::isfinite(tau) ? detail::format_number(tau) : std::string("not finite")) +
                                        ": expected a finite delay >= 0");
        d.push_back(tau);
    }
    return d;
}

std::vector<double> ExpressionSystem::delay_derivatives(const std::vector<double>& p, int j) const {
    if (p.size() != parameter_names().size())
        throw std::invalid_argument(std::to_string(p.size()) + " parameter values: expected " + std::to_string(parameter_names().size()));
    if (j < 0 || j >= static_cast<int>(p.size()))
        throw std::invalid_argument("parameter index " + std::to_string(j) + ": expected 0.." + std::to_string(static_cast<int>(p.size()) - 1));
    std::vector<Dual<double>> pd(p.begin(), p.end());
    pd[static_cast<std::size_t>(j)].deriv = 1.0;
    std::vector<double> d;
    for (const Expression& e : m_parsed.delays) d.push_back(e.evaluate<Dual<double>>(nullptr, pd.data()).deriv);
    return d;
}

}  // namespace ddemap
