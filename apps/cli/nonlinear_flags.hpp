#pragma once
// The flag group of the commands on nonlinear DDEs (equilibria, hopf, orbits): the problem (--system FILE
// with expressions, or --model ov|idm --ring N with the model's parameters) and the free
// parameter (--par NAME --from A --to B).
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <Eigen/Core>

#include "ddemap/analysis/bifurcation/equilibrium_branch.hpp"
#include "ddemap/io/json.hpp"
#include "ddemap/problem/nonlinear_dde.hpp"

namespace ddemap::cli {

struct NonlinearProblemArgs {
    std::string system, model, ring, par, from, to;
    // empty: the model's default (ov: alpha 1, tau 1, v0 1, h_st 1, headway 2; idm: a 1, b 1.5,
    // v0 33.3, delta 4, eta 2, gap 20; th and tau required; acc: a_max 2, a_min -3, the others
    // required or from --car)
    std::string alpha, tau, v0, h_st, headway, a, b, delta, th, eta, gap, k1, k2, a_max, a_min;
    std::string car;  ///< --model acc: k1, k2, th, tau, eta of a calibrated car (the one car syntax)
    std::vector<CLI::Option*> model_flags;

    /// --system, --model, --ring, the model flags, --par, --from, --to (required).
    void add_to(CLI::App& app);

    struct Problem {
        std::unique_ptr<NonlinearDDE> system;
        std::vector<std::string> variables;
        Eigen::VectorXd guess;  ///< the equilibrium guess at --from
        double from = 0.0, to = 0.0;
        /// system or model (and ring), then every parameter other than --par with its value
        JsonObject inputs;
        std::map<std::string, std::string> units;  ///< of variables and parameters, where known (built-in rings)
        /// The unit of a variable or parameter ("" where unknown).
        std::string unit(const std::string& name) const {
            const auto it = units.find(name);
            return it == units.end() ? std::string() : it->second;
        }
    };
    /// ", ov ring of 5 cars" for a built-in ring, "" for a system file: the end of a figure's title.
    std::string ring_title() const { return model.empty() ? std::string() : ", " + model + " ring of " + ring + " cars"; }
    /// The problem, with --par checked (BadInput naming the known names) and --from != --to
    /// (BadInput); a built-in ring is set to --par = --from for its guess (the uniform flow).
    Problem load() const;
};

/// The second parameter of a two-parameter curve (hopf --par2, equilibria --par2): --from2 and
/// --to2 required, --par2 another parameter of the system, its held value in [--from2, --to2]
/// (BadInput naming the flag otherwise); the branch options `o` copied into `co` and the three
/// recorded in the problem's inputs.
void second_parameter(NonlinearProblemArgs::Problem& pb, const EquilibriumBranchOptions& o, const std::string& par2, const std::string& from2,
                      const std::string& to2, TwoParameterOptions& co);

}  // namespace ddemap::cli
