#include "commands.hpp"

namespace ddemap::cli {

const std::vector<Command>& command_table() {
    static const std::vector<Command> table = {
        {"roots", "rightmost characteristic roots of a ring of N identical cars, a mixed fleet, or any linear DDE",
         add_roots_flags, run_roots},
        {"string", "plant and string stability (sup |Gamma(iw)| and the peak norm ||h||_1) from the head-to-tail transfer function", add_string_flags, run_string},
        {"classify", "plant, ring and string verdicts of calibrated vehicles (default: the paper's 14 settings)",
         add_classify_flags, run_classify},
        {"design",
         "gains of one car that minimise sup |Gamma(iw)|, ||h||_1 or a spectral abscissa within bounds, or the nearest string-stable gains; "
         "the verdicts before and after, certified",
         add_design_flags, run_design},
        {"sweep",
         "grid sweep over two model parameters (each given as LO:HI:COUNT): spectral abscissa, unstable roots, sup|Gamma| "
         "and verdicts per point; writes PREFIX.csv, .json, .svg, -boundaries.csv",
         add_sweep_flags, run_sweep},
        {"boundary",
         "stability boundaries in a window of two parameters (each given as LO:HI) by pseudo-arclength continuation; "
         "writes PREFIX.csv, .json",
         add_boundary_flags, run_boundary},
        {"chart", "render a chart spec (TOML, see maps/) to PREFIX.svg", add_chart_flags, run_chart},
        {"paper", "the seed paper's main job: classification table on stdout, figures and data under PREFIX", add_paper_flags,
         run_paper},
        {"simulate", "nonlinear platoon simulation behind a lead speed profile; writes PREFIX.csv, .json, .svg",
         add_simulate_flags, run_simulate},
        {"growth", "disturbance growth for every setting of the calibration table: platoons of 1 to 15 followers",
         add_growth_flags, run_growth},
        {"calibrate", "fit OVRV (k1, k2, th, tau, eta) to measured car-following traces (least squares with exact sensitivities, multistart Levenberg-Marquardt)",
         add_calibrate_flags, run_calibrate},
        {"mix", "penetration-rate study: spectral abscissa of a ring with a fraction p of type X among type Y",
         add_mix_flags, run_mix},
        {"equilibria", "a branch of equilibria of a nonlinear DDE (--system FILE with expressions, or --model ov|idm --ring N) in one parameter: "
         "stability at every point, folds and Hopf points",
         add_equilibria_flags, run_equilibria},
        {"hopf", "Hopf points of a nonlinear DDE on its equilibrium branch with their criticality (first Lyapunov coefficient), "
         "crossing speed and predicted orbit amplitude; with --par2 the Hopf curves in two parameters",
         add_hopf_flags, run_hopf},

        {"atlas", "the sweep's quantities and verdicts over a grid of up to five parameters and ring sizes (a TOML spec): "
         "OpenMP threads and MPI ranks (mpirun), resumable (--resume); writes DIR/atlas.h5 (HDF5) and DIR/atlas.svg",
         add_atlas_flags, run_atlas},

        {"orbits", "the branch of periodic orbits from a Hopf point of a nonlinear DDE (--system FILE or --model ov|idm --ring N) in one parameter: "
         "period, amplitude, Floquet stability, folds, period doublings, tori; --svg the bifurcation diagram",
         add_orbits_flags, run_orbits},
        {"bistability", "where stable stop-and-go waves coexist with stable uniform flow, in two parameters: Hopf curves with their "
         "criticality, curves of folds of periodic orbits, and the cells of the box they cut decided by slices; writes PREFIX.svg, .json, -curves.csv",
         add_bistability_flags, run_bistability},
    };
    return table;
}

}  // namespace ddemap::cli
