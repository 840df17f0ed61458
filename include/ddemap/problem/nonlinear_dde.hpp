#pragma once
/// \file nonlinear_dde.hpp
/// A nonlinear delay differential equation with discrete, parameter-dependent delays,
///     x'(t) = f(x(t), x(t - tau_1(p)), ..., x(t - tau_m(p)); p),   x in R^n,
/// evaluated on the stacked argument u = (u_0, u_1, ..., u_m) = (x(t), x(t - tau_1), ...,
/// x(t - tau_m)) in R^{n (m + 1)}. Its first derivatives are exact (forward-mode dual numbers,
/// core/dual.hpp): the blocks A_k = D_{u_k} f (n x n) and df/dp_j. At an equilibrium x*
/// (f(x*, ..., x*; p) = 0) the linearisation is the LinearDDE
///     y'(t) = A_0 y(t) + sum_k A_k y(t - tau_k),   A_k = D_{u_k} f(x*, ..., x*; p).

#include <map>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "ddemap/core/dual.hpp"
#include "ddemap/core/parameters.hpp"
#include "ddemap/problem/linear_dde.hpp"

namespace ddemap {

/// The system interface: implementations give the dimension, the parameter names, the delays as
/// functions of the parameters and f for doubles and for dual numbers (usually one template,
/// see NonlinearDDEOf). Parameters are held by the object (names fixed, values settable).
class NonlinearDDE {
public:
    using Dual2 = Dual<Dual<double>>;
    using Dual3 = Dual<Dual<Dual<double>>>;
    using Dual4 = Dual<Dual3>;
    using Dual5 = Dual<Dual4>;

    NonlinearDDE(std::vector<std::string> names, std::vector<double> values);
    virtual ~NonlinearDDE() = default;

    /// n, the dimension of x.
    virtual int dimension() const = 0;
    /// m, the number of delays (fixed; a delay may be 0 or equal another for some parameters).
    virtual int delay_count() const = 0;
    /// tau_1(p), ..., tau_m(p) for parameter values p (in the order of parameter_names()).
    virtual std::vector<double> delays(const std::vector<double>& p) const = 0;
    /// The delays at the current parameter values.
    std::vector<double> delays() const { return delays(m_values); }
    /// d tau_k / d p_j (k = 1..m) at parameter values p, exact (for the Jacobians of defining
    /// systems in a parameter that moves a delay). The default throws std::logic_error; the
    /// expression systems and the built-in models implement it (has_delay_derivatives()).
    virtual std::vector<double> delay_derivatives(const std::vector<double>& p, int j) const;
    /// True when delay_derivatives() is implemented.
    virtual bool has_delay_derivatives() const { return false; }

    const std::vector<std::string>& parameter_names() const { return m_names; }
    const std::vector<double>& parameter_values() const { return m_values; }
    /// Names and current values.
    ParameterMap parameters() const;
    double parameter(const std::string& name) const;
    /// Sets one value (std::invalid_argument for an unknown name or a non-finite value).
    void set_parameter(const std::string& name, double value);
    /// Index of a parameter (std::invalid_argument naming the known ones when unknown).
    int parameter_index(const std::string& name) const;

    /// f(u; p) for the stacked argument u of size n (m + 1).
    Eigen::VectorXd f(const Eigen::VectorXd& stacked) const;
    /// A_k = D_{u_k} f(u; p), k = 0..m (n x n), exact.
    Eigen::MatrixXd jacobian(const Eigen::VectorXd& stacked, int block) const;
    /// All blocks A_0..A_m at once (n (m + 1) dual evaluations).
    std::vector<Eigen::MatrixXd> jacobians(const Eigen::VectorXd& stacked) const;
    /// The same at parameter values p (in the order of parameter_names()), not the held ones.
    std::vector<Eigen::MatrixXd> jacobians(const Eigen::VectorXd& stacked, const std::vector<double>& p) const;
    /// f(u; p) at parameter values p.
    Eigen::VectorXd f(const Eigen::VectorXd& stacked, const std::vector<double>& p) const;
    /// df/dp_j at parameter values p (j the parameter's index), exact.
    Eigen::VectorXd parameter_derivative(const Eigen::VectorXd& stacked, int j, const std::vector<double>& p) const;
    /// df/dp for the named parameter, exact.
    Eigen::VectorXd parameter_derivative(const Eigen::VectorXd& stacked, const std::string& name) const;
    /// The stacked argument (x, x, ..., x) of a constant history.
    Eigen::VectorXd stack_constant(const Eigen::VectorXd& x) const;

    /// f evaluated in double arithmetic: u of size n (m + 1), p of the parameter count, out of size n.
    virtual void evaluate(const double* u, const double* p, double* out) const = 0;
    /// The same in dual numbers (derivatives along the seeded direction).
    virtual void evaluate(const Dual<double>* u, const Dual<double>* p, Dual<double>* out) const = 0;
    /// Nested dual numbers (derivatives of order 2 to 5; the fourth and fifth for the second
    /// Lyapunov coefficient). Systems built on NonlinearDDEOf have them; the default throws
    /// std::logic_error (see has_higher_derivatives()).
    virtual void evaluate(const Dual2* u, const Dual2* p, Dual2* out) const;
    virtual void evaluate(const Dual3* u, const Dual3* p, Dual3* out) const;
    virtual void evaluate(const Dual4* u, const Dual4* p, Dual4* out) const;
    virtual void evaluate(const Dual5* u, const Dual5* p, Dual5* out) const;
    /// True when the nested evaluate() overloads are implemented.
    virtual bool has_higher_derivatives() const { return false; }

    /// D^2_u f(u; p)[a, b] = sum_{ij} d^2 f / du_i du_j a_i b_j (stacked directions a, b), exact
    /// (one evaluation in Dual<Dual<double>> seeded u + a e1 + b e2).
    Eigen::VectorXd second_derivative(const Eigen::VectorXd& stacked, const Eigen::VectorXd& a, const Eigen::VectorXd& b) const;
    /// D^3_u f(u; p)[a, b, c], exact (one evaluation in three nested levels).
    Eigen::VectorXd third_derivative(const Eigen::VectorXd& stacked, const Eigen::VectorXd& a, const Eigen::VectorXd& b,
                                     const Eigen::VectorXd& c) const;
    /// The same two at parameter values p (in the order of parameter_names()), not the held ones.
    Eigen::VectorXd second_derivative(const Eigen::VectorXd& stacked, const std::vector<double>& p, const Eigen::VectorXd& a,
                                      const Eigen::VectorXd& b) const;
    Eigen::VectorXd third_derivative(const Eigen::VectorXd& stacked, const std::vector<double>& p, const Eigen::VectorXd& a,
                                     const Eigen::VectorXd& b, const Eigen::VectorXd& c) const;

protected:
    void check_stacked(const Eigen::VectorXd& stacked, const char* what) const;

private:
    std::vector<std::string> m_names;
    std::vector<double> m_values;
};

/// Implements both evaluate() overloads from one member template of Derived:
///     template <class T> void rhs(const T* u, const T* p, T* out) const;
/// (u_k = u + k n is the k-th delayed state). Nesting levels of dual numbers can be added here
/// for higher derivatives without touching the models.
template <class Derived>
class NonlinearDDEOf : public NonlinearDDE {
public:
    using NonlinearDDE::NonlinearDDE;
    void evaluate(const double* u, const double* p, double* out) const override {
        static_cast<const Derived*>(this)->rhs(u, p, out);
    }
    void evaluate(const Dual<double>* u, const Dual<double>* p, Dual<double>* out) const override {
        static_cast<const Derived*>(this)->rhs(u, p, out);
    }
    void evaluate(const Dual2* u, const Dual2* p, Dual2* out) const override { static_cast<const Derived*>(this)->rhs(u, p, out); }
    void evaluate(const Dual3* u, const Dual3* p, Dual3* out) const override { static_cast<const Derived*>(this)->rhs(u, p, out); }
    void evaluate(const Dual4* u, const Dual4* p, Dual4* out) const override { static_cast<const Derived*>(this)->rhs(u, p, out); }
    void evaluate(const Dual5* u, const Dual5* p, Dual5* out) const override { static_cast<const Derived*>(this)->rhs(u, p, out); }
    bool has_higher_derivatives() const override { return true; }
};

/// The linearisation at the equilibrium x*: A_k = D_{u_k} f(x*, ..., x*; p) with the delays
/// tau_k(p); delays 0 fold into A_0 and equal delays merge (LinearDDE). Throws
/// std::invalid_argument when x* has the wrong size or a non-finite entry. (x* need not be an
/// equilibrium: see equilibrium_residual.)
LinearDDE linearise(const NonlinearDDE& system, const Eigen::VectorXd& equilibrium);
/// The same at parameter values p instead of the held ones.
LinearDDE linearise(const NonlinearDDE& system, const Eigen::VectorXd& equilibrium, const std::vector<double>& p);

/// max_i |f_i(x*, ..., x*; p)|: 0 at an equilibrium.
double equilibrium_residual(const NonlinearDDE& system, const Eigen::VectorXd& equilibrium);

}  // namespace ddemap
