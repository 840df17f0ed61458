#pragma once
/// \file nonlinear_ring.hpp
/// The built-in nonlinear car-following rings by name, the one place where the command line and
/// the Python module make them: "ov" (OvRing: alpha, tau, v0, h_st, headway), "idm" (IdmRing:
/// a, b, v0, delta, th, eta, tau, gap) and "acc" (AccRing, the seed paper's OVRV law with
/// acceleration limits: k1, k2, th, tau, eta, a_max, a_min, gap), with the names of their states
/// and the units.

#include <map>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "ddemap/core/types.hpp"
#include "ddemap/problem/nonlinear_dde.hpp"

namespace ddemap {

struct NonlinearRing {
    std::unique_ptr<NonlinearDDE> system;
    std::vector<std::string> variables;           ///< h0.. (ov) or s0.. (idm), then v0..
    std::map<std::string, std::string> units;     ///< of the variables and the parameters
    Eigen::VectorXd uniform_flow;                 ///< the equilibrium at the parameters given
};

/// The ring names make_nonlinear_ring knows: {"ov", "idm", "acc"}.
std::vector<std::string> nonlinear_ring_models();
/// The parameter names of a ring model, in the order of its system (std::invalid_argument for
/// an unknown model).
std::vector<std::string> nonlinear_ring_parameters(const std::string& model);

/// The ring `model` of `cars` cars (2..2000) with the named parameters; a parameter not given
/// takes its default (ov: alpha 1, tau 1, v0 1, h_st 1, headway 2; idm: a 1, b 1.5, v0 33.3,
/// delta 4, eta 2, gap 20; idm's th and tau are required; acc: a_max 2, a_min -3, the others
/// required). std::invalid_argument naming the
/// value for an unknown model, a parameter the model does not have, a missing required one, or
/// values without a uniform flow (idm: gap <= eta).
NonlinearRing make_nonlinear_ring(const std::string& model, int cars, const ParameterMap& parameters);
/// The same with the free parameter of a branch set to its start value first (when it is a
/// parameter of the ring; otherwise the name is left to the caller's check), so that the uniform
/// flow is the equilibrium at the start of the branch.
NonlinearRing make_nonlinear_ring(const std::string& model, int cars, ParameterMap parameters, const std::string& free_parameter, double start);

}  // namespace ddemap
