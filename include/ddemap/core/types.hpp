#pragma once
/// \file types.hpp
/// The scalar, matrix and parameter types every layer shares.

#include <complex>
#include <map>
#include <string>

#include <Eigen/Dense>

namespace ddemap {

using cplx = std::complex<double>;
using MatrixXc = Eigen::MatrixXcd;
using VectorXc = Eigen::VectorXcd;

/// Named parameter values, e.g. {"k1": 0.2, "tau": 0.5}.
using ParameterMap = std::map<std::string, double>;

}  // namespace ddemap
