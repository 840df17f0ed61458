#pragma once
/// \file expression.hpp
/// Right-hand sides written as text: a recursive-descent parser compiles an expression such as
///     -d*x2 - a*x1 - x1^3 - b*(x1 - x1(t - tau))
/// into a postfix program that evaluates in double arithmetic and in (nested) dual numbers
/// (core/dual.hpp), so that the derivatives of a system read from a file are exact.
///
/// Grammar (whitespace is ignored between tokens):
///     expr    := term  (('+' | '-') term)*
///     term    := unary (('*' | '/') unary)*
///     unary   := ('-' | '+') unary | power
///     power   := primary ('^' unary)?              (right-associative: -x^2 = -(x^2), 2^-1 = 0.5)
///     primary := NUMBER | NAME | NAME '(' args ')' | '(' expr ')'
/// NUMBER as in C (1, 0.5, .5, 1e-3); NAME a variable, a parameter or a function: exp, log, sqrt,
/// sin, cos, tan, tanh, abs (one argument), min, max, pow (two). A delayed value is written
/// VARIABLE(t - DELAY) with DELAY an expression of parameters and numbers only (VARIABLE(t) is
/// the current value). Sub-expressions of numbers only are folded to one number.
/// Errors are std::invalid_argument "<where>, character <c>: <what>: expected <what>", with c the
/// 1-based position in the text.

#include <cmath>
#include <string>
#include <vector>

#include "ddemap/core/dual.hpp"

namespace ddemap {

/// One compiled expression: a postfix program over the stacked state u (u[k n + i] is variable i
/// delayed by delay k, k = 0 the current value) and the parameters p.
class Expression {
public:
    enum class Op : unsigned char {
        Number, State, Parameter,
        Add, Sub, Mul, Div, Pow, PowNumber, Neg,
        Exp, Log, Sqrt, Sin, Cos, Tan, Tanh, Abs, Min, Max
    };
    struct Instruction {
        Op op = Op::Number;
        int index = 0;        ///< State: index into u; Parameter: index into p
        double number = 0.0;  ///< Number: the value; PowNumber: the exponent
        bool operator==(const Instruction& o) const { return op == o.op && index == o.index && number == o.number; }
    };

    Expression() = default;
    explicit Expression(std::vector<Instruction> program);

    const std::vector<Instruction>& program() const { return m_program; }
    /// True when the program reads no state (an expression of parameters and numbers).
    bool is_parameter_only() const;
    bool operator==(const Expression& o) const { return m_program == o.m_program; }

    /// The value at (u, p) for T = double, Dual<double>, Dual<Dual<double>>, ...
    template <class T>
    T evaluate(const T* u, const T* p) const;

private:
    std::vector<Instruction> m_program;
    int m_depth = 0;  // largest evaluation stack
};

/// The names an expression may use.
struct ExpressionNames {
    std::vector<std::string> variables;   ///< the state x_1..x_n (may be delayed)
    std::vector<std::string> parameters;
    /// The name is a function, the time `t`, or not an identifier [A-Za-z_][A-Za-z0-9_]*:
    /// std::invalid_argument saying which (for checking the names a system declares).
    static void check_name(const std::string& name, const std::string& what);
};

/// Equations parsed together: each delayed value gets a delay slot; equal delay expressions share
/// one. In the compiled equations, u[k n + i] is variable i at t - delays[k - 1] (k >= 1).
struct ParsedEquations {
    std::vector<Expression> equations;
    std::vector<Expression> delays;  ///< parameter-only expressions tau_k(p)
    std::vector<std::string> delay_texts;  ///< the source text of each delay (for messages)
};

/// Parses equation j as "equation j+1 (d NAME/dt)" in messages. std::invalid_argument on a syntax
/// error, an unknown name, a delay that depends on the state, or a wrong function arity.
ParsedEquations parse_equations(const std::vector<std::string>& equations, const ExpressionNames& names);

/// One expression of parameters and numbers only (a delay, a parameter formula); `where` starts
/// the error messages.
Expression parse_parameter_expression(const std::string& text, const std::vector<std::string>& parameters,
                                      const std::string& where);

// ---------------------------------------------------------------------------------------------
// evaluation (a template, so that every level of dual numbers uses the same program)

namespace expression_detail {
inline bool is_zero(double x) { return x == 0.0; }
template <class T>
bool is_zero(const Dual<T>& x) { return is_zero(x.value) && is_zero(x.deriv); }

inline double power(double a, double b) { return std::pow(a, b); }
/// a^b with both varying: (a^b, b a^{b-1} a' + a^b log(a) b'); the log term is left out when
/// b' = 0, so that a negative base with a constant integer exponent stays finite.
template <class T>
Dual<T> power(const Dual<T>& a, const Dual<T>& b) {
    const T v = power(a.value, b.value);
    T d = b.value * power(a.value, b.value - 1.0) * a.deriv;
    if (!is_zero(b.deriv)) d = d + v * log(a.value) * b.deriv;
    return {v, d};
}
inline double power_number(double a, double c) { return std::pow(a, c); }
template <class T>
Dual<T> power_number(const Dual<T>& a, double c) { return pow(a, c); }
}  // namespace expression_detail

template <class T>
T Expression::evaluate(const T* u, const T* p) const {
    using std::cos;
    using std::exp;
    using std::log;
    using std::sin;
    using std::sqrt;
    using std::tanh;
    std::vector<T> s;
    s.reserve(static_cast<std::size_t>(m_depth));
    for (const Instruction& in : m_program) {
        switch (in.op) {
        case Op::Number: s.push_back(T(in.number)); break;
        case Op::State: s.push_back(u[in.index]); break;
        case Op::Parameter: s.push_back(p[in.index]); break;
        case Op::Neg: s.back() = -s.back(); break;
        case Op::Exp: s.back() = exp(s.back()); break;
        case Op::Log: s.back() = log(s.back()); break;
        case Op::Sqrt: s.back() = sqrt(s.back()); break;
        case Op::Sin: s.back() = sin(s.back()); break;
        case Op::Cos: s.back() = cos(s.back()); break;
        case Op::Tan: s.back() = sin(s.back()) / cos(s.back()); break;
        case Op::Tanh: s.back() = tanh(s.back()); break;
        case Op::Abs: if (s.back() < 0.0) s.back() = -s.back(); break;
        case Op::PowNumber: s.back() = expression_detail::power_number(s.back(), in.number); break;
        default: {
            const T b = s.back();
            s.pop_back();
            T& a = s.back();
            switch (in.op) {
            case Op::Add: a = a + b; break;
            case Op::Sub: a = a - b; break;
            case Op::Mul: a = a * b; break;
            case Op::Div: a = a / b; break;
            case Op::Pow: a = expression_detail::power(a, b); break;
            case Op::Min: if (b < a) a = b; break;
            case Op::Max: if (b > a) a = b; break;
            default: break;
            }
        }
        }
    }
    return s.empty() ? T(0.0) : s.back();
}

}  // namespace ddemap
