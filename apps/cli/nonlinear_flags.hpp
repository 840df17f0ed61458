#pragma once
// The flag group of the commands on nonlinear DDEs (equilibria, hopf): the problem (--system FILE
// with expressions, or --model ov --ring N with the ov parameters) and the free parameter
// (--par NAME --from A --to B).
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <Eigen/Core>

#include "ddemap/io/json.hpp"
#include "ddemap/problem/nonlinear_dde.hpp"

namespace ddemap::cli {

struct NonlinearProblemArgs {
    std::string system, model, ring, par, from, to;
    std::string alpha = "1", tau = "1", v0 = "1", h_st = "1", headway = "2";
    std::vector<CLI::Option*> ov_flags;

    /// --system, --model, --ring, the ov flags, --par, --from, --to (required).
    void add_to(CLI::App& app);

    struct Problem {
        std::unique_ptr<NonlinearDDE> system;
        std::vector<std::string> variables;
        Eigen::VectorXd guess;  ///< the equilibrium guess at --from
        double from = 0.0, to = 0.0;
        /// system or model (and ring), then every parameter other than --par with its value
        JsonObject inputs;
    };
    /// The problem, with --par checked (BadInput naming the known names) and --from != --to
    /// (BadInput); the ov ring is set to --par = --from for its guess (the uniform flow).
    Problem load() const;
};

}  // namespace ddemap::cli
