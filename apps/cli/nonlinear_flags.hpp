#pragma once
// The flags that choose a nonlinear DDE (equilibria, orbits): --system FILE, or --model ov
// --ring N with the ov ring's parameters. Parsing only.
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common.hpp"
#include "ddemap/problem/nonlinear_dde.hpp"

namespace ddemap::cli {

struct NonlinearSystemArgs {
    std::string system, model, ring;
    std::string alpha = "1", tau = "1", v0 = "1", h_st = "1", headway = "2";
    std::vector<CLI::Option*> ov_flags;

    void add_to(CLI::App& app);

    struct Built {
        std::unique_ptr<NonlinearDDE> system;
        std::vector<std::string> variables;
        Eigen::VectorXd guess;  ///< the file's "equilibrium", or the ring's uniform flow at p = from
        JsonObject inputs;      ///< system/model, ring, and every parameter but `par`
        std::map<std::string, std::string> units;  ///< of variables and parameters, where known
    };
    /// The system; `par` must be one of its parameters (bad input naming the known ones). For
    /// the ov ring `par` is set to `from` first (the uniform flow there is the guess).
    Built build(const std::string& par, double from) const;
};

}  // namespace ddemap::cli
