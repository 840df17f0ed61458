#pragma once
/// \file dual.hpp
/// Forward-mode automatic differentiation with dual numbers: a + b e with e^2 = 0, so that
///     g(a + b e) = g(a) + g'(a) b e
/// for every g built from the operations below. Dual<double> gives exact first derivatives
/// (one direction per evaluation). The value and derivative parts are themselves of type T,
/// so Dual<Dual<double>> (seeded a + e1 + e2) gives second derivatives in its e1 e2 part, and
/// a third level third derivatives: higher orders need no new code, only nesting.

#include <cmath>
#include <type_traits>

namespace ddemap {

template <class T>
struct Dual {
    T value{};  ///< a
    T deriv{};  ///< b: the directional derivative

    constexpr Dual() = default;
    /// A constant: derivative 0.
    constexpr Dual(double c) : value(c), deriv(0.0) {}  // NOLINT: implicit by design (constants in formulas)
    constexpr Dual(T v, T d) : value(v), deriv(d) {}

    Dual& operator+=(const Dual& o) { value += o.value; deriv += o.deriv; return *this; }
    Dual& operator-=(const Dual& o) { value -= o.value; deriv -= o.deriv; return *this; }
    Dual& operator*=(const Dual& o) { deriv = deriv * o.value + value * o.deriv; value *= o.value; return *this; }
    Dual& operator/=(const Dual& o) {
        const T inv = T(1.0) / o.value;
        value *= inv;
        deriv = (deriv - value * o.deriv) * inv;
        return *this;
    }
};

/// The value of a (possibly nested) dual number, or the number itself.
inline double value_of(double x) { return x; }
template <class T>
double value_of(const Dual<T>& x) { return value_of(x.value); }

template <class T> Dual<T> operator+(Dual<T> a, const Dual<T>& b) { return a += b; }
template <class T> Dual<T> operator-(Dual<T> a, const Dual<T>& b) { return a -= b; }
template <class T> Dual<T> operator*(Dual<T> a, const Dual<T>& b) { return a *= b; }
template <class T> Dual<T> operator/(Dual<T> a, const Dual<T>& b) { return a /= b; }
template <class T> Dual<T> operator-(const Dual<T>& a) { return {-a.value, -a.deriv}; }
template <class T> Dual<T> operator+(const Dual<T>& a) { return a; }

// mixed with plain numbers (doubles), so that formulas like 2.0 * x read as usual
template <class T> Dual<T> operator+(Dual<T> a, double b) { a.value += b; return a; }
template <class T> Dual<T> operator+(double a, Dual<T> b) { b.value += a; return b; }
template <class T> Dual<T> operator-(Dual<T> a, double b) { a.value -= b; return a; }
template <class T> Dual<T> operator-(double a, const Dual<T>& b) { return {a - b.value, -b.deriv}; }
template <class T> Dual<T> operator*(const Dual<T>& a, double b) { return {a.value * b, a.deriv * b}; }
template <class T> Dual<T> operator*(double a, const Dual<T>& b) { return {a * b.value, a * b.deriv}; }
template <class T> Dual<T> operator/(const Dual<T>& a, double b) { return {a.value / b, a.deriv / b}; }
template <class T> Dual<T> operator/(double a, const Dual<T>& b) {
    const T q = a / b.value;
    return {q, -q * b.deriv / b.value};
}

// comparisons look at the value only (branches of a law are taken as in double arithmetic)
template <class T> bool operator<(const Dual<T>& a, const Dual<T>& b) { return value_of(a) < value_of(b); }
template <class T> bool operator>(const Dual<T>& a, const Dual<T>& b) { return value_of(a) > value_of(b); }
template <class T> bool operator<=(const Dual<T>& a, const Dual<T>& b) { return value_of(a) <= value_of(b); }
template <class T> bool operator>=(const Dual<T>& a, const Dual<T>& b) { return value_of(a) >= value_of(b); }
template <class T> bool operator<(const Dual<T>& a, double b) { return value_of(a) < b; }
template <class T> bool operator>(const Dual<T>& a, double b) { return value_of(a) > b; }
template <class T> bool operator<=(const Dual<T>& a, double b) { return value_of(a) <= b; }
template <class T> bool operator>=(const Dual<T>& a, double b) { return value_of(a) >= b; }

// elementary functions: (g(a), g'(a) b); written with T so that nesting recurses
using std::cos;
using std::exp;
using std::log;
using std::pow;
using std::sin;
using std::sqrt;
using std::tanh;

template <class T> Dual<T> exp(const Dual<T>& a) {
    const T e = exp(a.value);
    return {e, e * a.deriv};
}
template <class T> Dual<T> log(const Dual<T>& a) { return {log(a.value), a.deriv / a.value}; }
template <class T> Dual<T> sqrt(const Dual<T>& a) {
    const T r = sqrt(a.value);
    return {r, a.deriv / (2.0 * r)};
}
template <class T> Dual<T> sin(const Dual<T>& a) { return {sin(a.value), cos(a.value) * a.deriv}; }
template <class T> Dual<T> cos(const Dual<T>& a) { return {cos(a.value), -sin(a.value) * a.deriv}; }
template <class T> Dual<T> tanh(const Dual<T>& a) {
    const T t = tanh(a.value);
    return {t, (1.0 - t * t) * a.deriv};
}
/// a^c for a constant exponent: (a^c, c a^{c-1} b). At a = 0 the derivative part is 0 for c > 1.
template <class T> Dual<T> pow(const Dual<T>& a, double c) {
    if (c == 0.0) return Dual<T>(1.0);
    return {pow(a.value, c), c * pow(a.value, c - 1.0) * a.deriv};
}
/// a^c with both varying: exp(c log a) (a > 0).
template <class T> Dual<T> pow(const Dual<T>& a, const Dual<T>& c) { return exp(c * log(a)); }
/// c^a for a constant base c > 0.
template <class T> Dual<T> pow(double c, const Dual<T>& a) { return exp(a * std::log(c)); }

/// The seed x + 1 e: a variable whose derivative is wanted.
template <class T>
Dual<T> variable(T x) { return {x, T(1.0)}; }

}  // namespace ddemap
