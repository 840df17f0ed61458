#pragma once
/// \file periodic_orbit.hpp
/// Periodic orbits of a nonlinear DDE x'(t) = f(x(t), x(t - tau_1), ..., x(t - tau_m); p)
/// (problem/nonlinear_dde.hpp) and their branches in one parameter p.
///
/// Discretisation (discretize/periodic_mesh.hpp): time scaled by the period T, s = t / T in
/// [0, 1], x is a continuous piecewise polynomial of degree d on L intervals, given by its
/// values at the L d mesh points (x(1) = x(0)). The equations are
///     x'(c) = T f(x(c), x((c - tau_1 / T) mod 1), ..., x((c - tau_m / T) mod 1); p)
/// at the L d Gauss-Legendre collocation points c (delayed values by the piecewise polynomial's
/// Lagrange interpolation), and the integral phase condition against a reference orbit x_ref
/// (the previous orbit of the branch),  int_0^1 x(s) . x_ref'(s) ds = 0  (Gauss quadrature,
/// exact for these polynomials): L d n + 1 equations in the L d n + 2 unknowns (x, T, p).
/// Newton's Jacobian is exact: the blocks A_k = D_{u_k} f and df/dp from dual numbers, and
///     dF/dT = -f - sum_k A_k x'(c_k) tau_k / T,
///     dF/dp = -T df/dp + sum_k A_k x'(c_k) d tau_k / dp        (c_k = c - tau_k / T);
/// bordered by the phase row and the pseudo-arclength row. It is solved in condensed form: the
/// collocation matrix of the points of one period is block lower triangular by intervals (a
/// delayed point is never later than its collocation point) once the values on the history
/// window [-max tau / T, 0] are taken as separate unknowns, so a forward sweep over the
/// intervals (dense d n x d n diagonal blocks) reduces the Newton system exactly to a dense
/// one in the window values, T and p (the monodromy matrix minus the identity, bordered); the
/// same sweep gives the Floquet monodromy matrix. Chord steps reuse the linearisation of the
/// previous orbit, a new one is made when a step contracts by less than 0.3, and one at every
/// orbit found (for its tangent, its multipliers and the next corrector). Windows of more than
/// 4000 values use Eigen's supernodal SparseLU (COLAMD) of the whole bordered Jacobian instead.
///
/// Mesh adaptation (options.adapt, off by default): after every orbit the breakpoints are moved so that they
/// equidistribute |x^(d+1)|^(1/(d+1)) (estimated from the jumps of the piecewise constant d-th
/// derivative between intervals), as in COLSYS and DDE-BIFTOOL, and the orbit and the tangent
/// are interpolated onto the new mesh before the next step.
///
/// Continuation: pseudo-arclength in the weighted norm
///     |u|^2 = (1 / (L d)) sum_i |x_i|^2 / sx^2 + (T / sT)^2 + (p / sp)^2
/// (sx = 1, sT = the first period, sp = |to - from|), tangent predictor, step halved on a
/// failed corrector and grown by 1.5 after an easy one. From a Hopf point (x*, p_H, omega, q):
/// the first orbit is corrected from x* + eps Re(q e^{2 pi i s}), T = 2 pi / omega, p = p_H
/// with the step condition along that direction (the equilibrium is excluded by it).
///
/// Floquet multipliers (DDE-BIFTOOL's approach, Engelborghs et al. 2000): the collocation
/// equations of the variational equation y' = T (A_0(s) y(s) + sum_k A_k(s) y(s - tau_k / T))
/// on [0, 1], M1 y_new + M0 y_hist = 0, with y_hist the mesh values (the mesh repeated
/// periodically) on the intervals that meet [-max tau_k / T, 0]; the monodromy matrix maps
/// y_hist to the values on the same points shifted by one period (rows of -M1^{-1} M0 or of the
/// identity), and its eigenvalues are the multipliers (the zero multipliers of the points that
/// no delay reaches are left out): all of them (dense QR) for matrices up to 200, else the
/// largest by Arnoldi (Spectra; at least 16, and every one of modulus above 1/2; each Ritz
/// pair's residual checked, dense QR when one fails). The trivial multiplier (the one nearest 1, of
/// the eigenvector x') must be 1: |mu_trivial - 1| is the accuracy check.
///
/// Special points along a branch: a fold (the parameter component of the unit tangent changes
/// sign) is located by Illinois regula falsi in the arclength on that component (each trial
/// orbit corrected); a period doubling (a real negative multiplier crosses the unit circle) and a
/// torus bifurcation (a complex pair crosses it) likewise on |mu| - 1 of the multiplier that
/// crosses (OrbitCrossing). The multipliers of each kind of two consecutive orbits are paired
/// by distance, so every crossing of a step is found, also several in one long step; a change of
/// the number of multipliers outside the circle without a crossing (two multipliers colliding on
/// the real axis) is not reported.

#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "ddemap/analysis/bifurcation/equilibrium_branch.hpp"
#include "ddemap/core/execution.hpp"
#include "ddemap/core/status.hpp"
#include "ddemap/core/types.hpp"
#include "ddemap/discretize/periodic_mesh.hpp"
#include "ddemap/problem/nonlinear_dde.hpp"

namespace ddemap {

struct PeriodicOrbitOptions {
    std::string parameter;   ///< the free parameter (a name of the system)
    double from = 0.0;       ///< the parameter range [min(from, to), max(from, to)]: the branch
    double to = 1.0;         ///< ends on its faces (located exactly)
    int degree = 4;          ///< d, the degree of the piecewise polynomials (1..20)
    int intervals = 40;      ///< L, the number of mesh intervals (>= 2)
    int max_points = 100;    ///< orbits on the branch, the first included (>= 2)
    double initial_step = 0.02;  ///< h in the weighted norm (also the first orbit's amplitude measure)
    /// the largest step h in the weighted norm |u| of the continuation (below): h grows by 1.5
    /// after an easy corrector up to it, and is halved after a failed one. The norm counts the
    /// root mean square of the profile's values, T / sT and p / |to - from|, so its size follows
    /// the orbits' amplitude: a branch whose orbits grow to an amplitude A needs about A / max_step
    /// orbits at least
    double max_step = 0.1;
    double min_step = 1e-6;  ///< the branch ends when the step falls below it
    int max_iterations = 10;      ///< Newton iterations per corrector
    double tolerance = 1e-10;     ///< Newton stops when max |du| <= tolerance * max(1, max |u|)
    double residual_tolerance = 1e-8;  ///< an orbit is accepted when max |F| <= this
    /// the branch ends when the period exceeds this multiple of the first period (a homoclinic orbit)
    double max_period_factor = 50.0;
    bool floquet = true;     ///< compute the multipliers (stability, period doublings, tori)
    /// move the mesh after every orbit so that it equidistributes |x^(d+1)|^(1/(d+1)) of that
    /// orbit (L and d kept; false: the uniform mesh throughout). Off by default: on Wright's
    /// equation at alpha = 2.9 (L = 40) it makes the period 3 times more accurate but the trivial
    /// multiplier 100 times less (6.8e-4 against 5.4e-6), and the history segment of the
    /// monodromy matrix (so its size) can grow where the mesh is fine near s = 1.
    bool adapt = false;
    /// After every orbit added to the branch, the first included: (orbits so far, max_points, p).
    /// It may throw to stop the branch; the exception reaches the caller (no partial branch).
    BranchProgress progress;
    bool is_valid(std::string* why = nullptr) const;
};

/// The accuracy check of an orbit's multipliers: |mu_trivial - 1| above this leaves its
/// stability undecided (accurate orbits have 1e-15 to 1e-5; near a homoclinic end it reaches 1).
inline constexpr double orbit_accuracy_limit = 1e-2;

/// One orbit: mesh values, period, parameter and what is derived from them.
struct PeriodicOrbit {
    double par = 0.0;
    double period = 0.0;
    Eigen::MatrixXd profile;  ///< L d x n: row i is x at mesh point i (x(1) = row 0)
    std::vector<double> breakpoints;  ///< the mesh t_0 = 0 < ... < t_L = 1 of the profile
    Eigen::VectorXd min, max;  ///< of every variable over the orbit (sampled at 8 d points per interval)
    /// by decreasing modulus, the trivial one included (for monodromy matrices above 200: the
    /// largest ones, at least 16 and all of modulus above 1/2)
    std::vector<cplx> multipliers;
    double trivial_distance = std::numeric_limits<double>::quiet_NaN();  ///< |mu_trivial - 1|
    double max_nontrivial = std::numeric_limits<double>::quiet_NaN();   ///< max |mu| over the others
    bool stable = false;      ///< every nontrivial |mu| < 1 (false without multipliers or when undecided)
    /// non-empty: the orbit failed its accuracy check (trivial_distance > orbit_accuracy_limit):
    /// no stability verdict (`stable` false, JSON null) and no special points next to it; the reason
    std::string undecided;
    double residual = std::numeric_limits<double>::infinity();  ///< max |F| (collocation and phase)
    int iterations = 0;       ///< Newton iterations of its corrector
};

struct OrbitFold {
    double par = 0.0, period = 0.0;
    PeriodicOrbit orbit;
    bool located = false;  ///< the regula falsi reached its tolerance
    int after = 0;         ///< index of the branch orbit before it
};

/// A period doubling or a torus bifurcation between orbits after and after + 1: the zero of
///     g(s) = |mu(s)| - 1
/// along the branch (s the arclength from orbit `after`, each trial orbit corrected and its
/// multipliers computed), mu the crossing real negative multiplier (period doubling) or complex
/// one (torus), followed from the two orbits' by continuity, by Illinois regula falsi from the
/// bracket of the two orbits until |g| <= 1e-9 (or the bracket is 1e-12 of the step); then an
/// orbit just beyond the zero is computed and must have g of the other sign: par_bracket is the
/// width of that verified bracket (a few 1e-8 of the step in the arclength, usually).
struct OrbitCrossing {
    double par = 0.0, period = 0.0;  ///< of the located orbit (not located: interpolated linearly in g)
    cplx multiplier;                  ///< the crossing multiplier there (torus: the one with Im >= 0)
    bool located = false;             ///< the regula falsi reached its tolerance
    /// | |mu| - 1 | of the crossing multiplier at the located orbit (NaN when not located)
    double accuracy = std::numeric_limits<double>::quiet_NaN();
    /// the width in p of the last bracket of the zero (NaN when not located)
    double par_bracket = std::numeric_limits<double>::quiet_NaN();
    PeriodicOrbit orbit;              ///< the located orbit (empty when not located)
    int after = 0;
};

struct OrbitBranch {
    std::string parameter;
    int degree = 0, intervals = 0;
    std::vector<PeriodicOrbit> points;
    std::vector<OrbitFold> folds;
    std::vector<OrbitCrossing> period_doublings, tori;
    /// Converged when the branch ended regularly (a face of the range, max_points, a period
    /// above max_period_factor, an equilibrium) with every orbit and fold located; MaxIterations /
    /// NumericalIssue when the first orbit failed or the step fell below min_step.
    Status status = Status::Converged;
    std::string message;
    /// why it ended: "bound" (a face of the range), "max_points", "period" (above
    /// max_period_factor), "hopf" (the amplitude fell below half the first orbit's: an
    /// equilibrium, usually another Hopf point), "period_doubling" (a branch of twice the period
    /// back on an orbit of the period halved: orbit_branch_from_period_doubling),
    /// "step_below_minimum", "first_orbit_failed"
    std::string stop;
    std::string method;   ///< the discretisation and solver used
    double max_residual = 0.0;          ///< certificate: max over orbits of max |F|
    double max_trivial_distance = 0.0;  ///< certificate: max over orbits of |mu_trivial - 1|
    int newton_iterations = 0;
    /// Jacobians evaluated and factorised by the correctors (condensed linearisations, or
    /// sparse LU factorisations where the history window is too large for the condensed form)
    int jacobians = 0;
};

/// A starting orbit (e.g. sampled from a simulation): values on the mesh of `mesh`, period, parameter.
struct OrbitGuess {
    double par = 0.0, period = 0.0;
    Eigen::MatrixXd profile;  ///< points() x n
};

/// The guess from samples of one period: times t_0 < ... (covering [t_0, t_0 + period]) and
/// states (one row per time), linearly interpolated at the mesh points t_0 + s period.
/// std::invalid_argument when the samples do not cover a period or sizes do not fit.
OrbitGuess orbit_guess_from_samples(const PeriodicMesh& mesh, const std::vector<double>& times, const Eigen::MatrixXd& states,
                                    double period, double par);

/// A starting orbit found by simulation (orbit_guess_from_simulation).
struct SimulatedOrbitGuess {
    OrbitGuess guess;  ///< the last full period of the run on the mesh (empty unless converged)
    /// Converged: the run settled on a periodic orbit; NumericalIssue: it settled on an
    /// equilibrium, did not repeat to the tolerance, or left the finite numbers (the message says which)
    Status status = Status::NumericalIssue;
    std::string message;
    double period = 0.0;           ///< mean of the last repeats
    double period_spread = 0.0;    ///< max |repeat - mean| / mean over the last third of the run
    int crossings_per_period = 0;  ///< upward crossings of the mean level per period (1 for a simple orbit)
    double amplitude = 0.0;        ///< max - min of the first variable over the last third
};

/// Simulates the system at its parameter values (DdeSolver: RK4 with a Hermite continuous
/// extension, step `step`) from the constant history `history` on [-max tau, 0] to `t_end`, and
/// reads a periodic orbit off the last third of the run: the upward crossings t_i of the first
/// variable through its mean level there, the smallest k (1..8) with
///     |t_{i+k} - t_i - T| <= 1e-3 T  for every i  (T their mean),
/// and the samples of [t_last - T, t_last] on `mesh` (orbit_guess_from_samples), par the
/// system's value of `parameter`. std::invalid_argument for sizes that do not fit, t_end or
/// step not > 0, or an unknown parameter; a run that does not settle is a status.
SimulatedOrbitGuess orbit_guess_from_simulation(const NonlinearDDE& system, const std::string& parameter, const PeriodicMesh& mesh,
                                                const Eigen::VectorXd& history, double t_end, double step);

/// The branch through the orbit a simulation settled on (orbit_branch_from_guess from g.guess);
/// when it did not settle (g.status not Converged) the branch is empty with that status, stop
/// "first_orbit_failed" and the simulation's message.
OrbitBranch orbit_branch_from_simulation(const NonlinearDDE& system, const SimulatedOrbitGuess& g, const PeriodicOrbitOptions& options);

/// The step of those simulations by default: 0.01, or a tenth of the shortest positive delay
/// when that is shorter (at the system's parameter values).
double default_simulation_step(const NonlinearDDE& system);

/// The branch from a Hopf point of an equilibrium branch (hopf.x, hopf.par, hopf.omega, hopf.q).
/// std::invalid_argument for invalid options, an unknown parameter, a system without delay
/// derivatives, or a Hopf point with omega <= 0 or q of the wrong size; non-convergence is a status.
OrbitBranch orbit_branch_from_hopf(const NonlinearDDE& system, const HopfPoint& hopf, const PeriodicOrbitOptions& options);

/// The branch through the orbit corrected from `guess` (the parameter fixed at guess.par for
/// that correction), followed in the direction of increasing p when to > from, else decreasing.
OrbitBranch orbit_branch_from_guess(const NonlinearDDE& system, const OrbitGuess& guess, const PeriodicOrbitOptions& options);

/// The branch of orbits of twice the period born at a located period doubling `pd` of a branch
/// (pd.orbit: the orbit of period T where the multiplier mu = -1). On the mesh of pd.orbit
/// traversed twice (2 L intervals of its degree; options.degree and options.intervals are not
/// used), the first orbit is corrected from
///     x(2 s) + eps y(s),  period 2 T,  p = pd.par,
/// with the step condition along (y, 0, 0): y the Floquet eigenfunction of mu (the eigenvector
/// of the monodromy matrix by inverse iteration on M - mu I, continued over [0, 1] by the
/// collocated variational equation, and y(s + 1) = mu y(s) on the second period), eps =
/// options.initial_step. On the doubled problem the old branch (its orbit traversed twice) goes on
/// through the point, so this direction (orthogonal to the old branch's tangent) selects the new
/// one. The branch ends, besides the ends of orbit_branch_from_hopf, when it returns to an orbit
/// of the period halved (stop "period_doubling"): the distance max_s |x(s) - x(s + 1/2)| falls
/// below half the first orbit's, or the parameter turns while it is below a quarter of its largest.
/// Period doublings of this branch are the next ones of a cascade. std::invalid_argument for a
/// period doubling that is not located or whose multiplier is not real near -1; a failed
/// eigenvector or first orbit is a status (stop "first_orbit_failed").
OrbitBranch orbit_branch_from_period_doubling(const NonlinearDDE& system, const OrbitCrossing& pd, const PeriodicOrbitOptions& options);

/// The Floquet multipliers (as in the branch, by decreasing modulus, the trivial one included)
/// of a given orbit of `system`: its values on `mesh` (points() x n), period and the value `par`
/// of `parameter` (the other parameters as held). Empty when they could not be computed (a
/// singular collocation matrix, a non-finite value, or a history segment above 4000 values).
/// std::invalid_argument for sizes that do not fit, a period <= 0 or an unknown parameter.
std::vector<cplx> orbit_multipliers(const NonlinearDDE& system, const std::string& parameter, const PeriodicMesh& mesh,
                                    const Eigen::MatrixXd& profile, double period, double par);

/// Options of a curve of folds of periodic orbits in two parameters (orbit_fold_curve).
struct OrbitFoldCurveOptions {
    /// the first parameter (parameter, from, to: its range), the mesh (degree, intervals; the
    /// uniform mesh, `adapt` is not used), the steps and tolerances of the continuation in the
    /// weighted norm of PeriodicOrbitOptions extended by (p2 / |to2 - from2|)^2, and max_points:
    /// the most points in each direction from the start
    PeriodicOrbitOptions orbit;
    std::string parameter2;  ///< the second parameter (a name of the system, not `orbit.parameter`)
    double from2 = 0.0;      ///< its range [min(from2, to2), max(from2, to2)]: the curve ends on its faces
    double to2 = 1.0;
    bool is_valid(std::string* why = nullptr) const;
};

/// One point of a fold curve: the orbit (with its Floquet multipliers when orbit.floquet) at
/// (par, par2) where the branch in `par` turns.
struct OrbitFoldCurvePoint {
    double par = 0.0, par2 = 0.0;
    PeriodicOrbit orbit;  ///< its par is `par`
    /// |g|, the fold test function of the bordered system (see orbit_fold_curve): 0 at a fold
    double test = std::numeric_limits<double>::quiet_NaN();
    /// an independent check from the Floquet multipliers: at a fold of orbits the trivial
    /// multiplier 1 is double, so the second nearest to 1 is near it too; |mu_2 - 1| (NaN
    /// without multipliers). The collocation splits the double multiplier like the square root
    /// of its error, so it is of the order of sqrt(trivial_distance)
    double second_distance = std::numeric_limits<double>::quiet_NaN();
    /// a torus curve's point: phi of its multipliers e^{+-i phi} on the unit circle, in (0, pi)
    /// (NaN on fold and period doubling curves); second_distance is then min |mu - e^{i phi}| over
    /// the orbit's Floquet multipliers
    double rotation = std::numeric_limits<double>::quiet_NaN();
};

/// A curve of folds of periodic orbits in (parameter, parameter2), ordered along the curve.
struct OrbitFoldCurve {
    std::string parameter, parameter2;
    int degree = 0, intervals = 0;
    std::vector<OrbitFoldCurvePoint> points;
    int start = 0;  ///< index of the point corrected from the given fold
    /// why each end ended: "bound" (a face of the box), "max_points", "period" (above
    /// max_period_factor times the start's: towards a homoclinic orbit), "hopf" (the amplitude fell
    /// below 2 % of the largest on the curve, or the curve turned back in (p1, p2) below a quarter of
    /// it, or a fold curve's corrector failed after the amplitude fell over its last 3 points to
    /// below a quarter of it: the fold system degenerates as a -> 0 and Newton stalls at ~1e-8
    /// of the fold's position: at a generalised Hopf point, where a fold curve meets the Hopf curve; a torus curve ends
    /// so at a double Hopf or zero-Hopf point: orbit_curve_end_point), "resonance" (a torus curve's
    /// phi within 0.01 of 0 or pi, or across them within a step),
    /// "step_below_minimum"; first the end before `start`, then the end after
    std::string stop_backward, stop_forward;
    Status status = Status::Converged;
    std::string message;
    std::string method;
    double max_residual = 0.0;          ///< certificate: max over points of max |F| (collocation and phase)
    double max_test = 0.0;              ///< certificate: max over points of |g|
    double max_trivial_distance = 0.0;  ///< max over points of |mu_trivial - 1| (with multipliers)
    int newton_iterations = 0;
};

/// The curve of folds of periodic orbits through the fold `fold` of a branch in
/// options.orbit.parameter (its orbit on the uniform mesh of options.orbit.degree and
/// .intervals: a branch computed with those and adapt off), followed in both directions in
/// (parameter, parameter2), parameter2 starting at its value in `system`.
///
/// The fold condition is appended to the collocation system (the minimally augmented system,
/// as DDE-BIFTOOL's and MatCont's folds of periodic orbits): with A = D_(x,T) [F; phase], the
/// square Jacobian of the collocation equations and the phase condition in the profile and the
/// period, and vectors b, c (the left and right null vectors of A at the previous point),
///     [A b; c^T 0] [v; g] = [0; 1]
/// defines the scalar g(x, T, p1, p2), zero exactly where A is singular: where the branch in p1
/// has a turning point (a fold). The unknowns (x, T, p1, p2) solve F = 0, phase = 0, g = 0 and the
/// pseudo-arclength condition; Newton's row of g is g_z = -w^T A_z v (w from the transposed
/// system), the second derivative w^T A_z v taken as a central difference of the Jacobian's
/// transpose times w along v: (J(z + e v)^T w - J(z - e v)^T w) / (2 e). Each Newton step is a
/// sparse LU of the (N + 3) square extended Jacobian. The phase reference is the previous point.
/// std::invalid_argument for invalid options, unknown parameters, parameter2 outside its range,
/// a fold whose profile does not fit the mesh; non-convergence is a status.
OrbitFoldCurve orbit_fold_curve(const NonlinearDDE& system, const OrbitFold& fold, const OrbitFoldCurveOptions& options);

/// The curve of period doublings through the located period doubling `pd` of a branch (its
/// orbit on the uniform mesh of the options, as for orbit_fold_curve), in (parameter,
/// parameter2): the same continuation with the period-doubling condition appended instead of the
/// fold's. A multiplier -1 of the orbit is a multiplier 1 of the orbit traversed twice with an
/// antiperiodic eigenfunction; with A_pd the collocated variational operator with the
/// antiperiodic wrap y(s + 1) = -y(s) (N x N: the Jacobian A2 of the collocation on the mesh
/// traversed twice, first-half rows, its first-half columns minus its second-half columns),
///     [A_pd b; c^T 0] [v; g] = [0; 1]
/// defines g, zero exactly where -1 is a multiplier; g_z = -w^T A_pd,z v is half the central
/// difference of A2^T (w, -w) along (v, -v) (a direction in which the doubled orbit stays
/// 2T-periodic, so that the symmetry of second derivatives applies), summed over the two copies of
/// the profile. In the points, `test` is |g| and `second_distance` the independent check
/// min |mu + 1| over the orbit's Floquet multipliers. std::invalid_argument as orbit_fold_curve,
/// and for a period doubling that is not located.
OrbitFoldCurve orbit_period_doubling_curve(const NonlinearDDE& system, const OrbitCrossing& pd, const OrbitFoldCurveOptions& options);

/// The curve of torus (Neimark-Sacker) bifurcations through the located torus bifurcation `torus`
/// of a branch (its orbit on the uniform mesh of the options), in (parameter, parameter2): the
/// same continuation with the torus condition appended and the angle phi of the multipliers
/// e^{+-i phi} as one more unknown. With A_mu the collocated variational operator with the
/// Floquet wrap y(s + 1) = mu y(s), mu = e^{i phi} (the profile Jacobian's parts that reach q
/// periods away weighted by mu^q; they are read off the collocation on the mesh traversed
/// ceil(tau_max / T) + 2 times),
///     [A_mu b; c^H 0] [v; g] = [0; 1]
/// defines the complex g, zero exactly where mu is a multiplier; Re g = Im g = 0 are the two
/// appended equations; g_z = -w^H A_mu,z v by central differences as for the period doubling,
/// g_phi exactly. A curve also ends ("resonance") where phi comes within 0.01 of 0 or pi (the
/// pair meets at 1 or -1: a fold or period doubling curve). In the points, `test` is |g|,
/// `rotation` phi and `second_distance` the independent check min |mu - e^{i phi}| over the
/// orbit's Floquet multipliers. std::invalid_argument as orbit_fold_curve, and for a torus
/// bifurcation that is not located or whose multiplier is (nearly) real.
OrbitFoldCurve orbit_torus_curve(const NonlinearDDE& system, const OrbitCrossing& torus, const OrbitFoldCurveOptions& options);

/// Where a torus curve that ended on its orbits' shrinking ("hopf") ends, from the point `end`:
/// "ZH" (a zero-Hopf point, where the torus's phi tends to 0 or pi: within 0.1) or "DH" (a double
/// Hopf point, phi tending to 2 pi omega2 / omega1 mod 2 pi).
std::string orbit_curve_end_point(const OrbitFoldCurvePoint& end);

/// The curves in two parameters through a branch's special points (orbit_curves_of_branch).
struct OrbitBranchCurves {
    std::vector<OrbitFoldCurve> folds, period_doublings, tori;
    /// the fold (period doubling, torus bifurcation) of the branch each curve starts from
    std::vector<int> fold_index, period_doubling_index, torus_index;
    Status status = Status::Converged;  ///< of the first curve that did not converge, with its message
    std::string message;
};

/// Every located fold of `branch` continued as a curve of folds (orbit_fold_curve), every
/// located period doubling as a curve of period doublings (orbit_period_doubling_curve) and every
/// located torus bifurcation as a curve of tori (orbit_torus_curve), in
/// (options.orbit.parameter, options.parameter2); a point that lies on a curve of its kind already
/// traced (a segment of it crosses the held parameter2 within 1e-6 of the first parameter's range
/// from the point) starts none. options.orbit.progress reports every curve's points.
OrbitBranchCurves orbit_curves_of_branch(const NonlinearDDE& system, const OrbitBranch& branch, const OrbitFoldCurveOptions& options);

/// x(s) of an orbit on `mesh` at s (any real: taken mod 1), all n components (for an orbit of a
/// branch: PeriodicMesh(branch.degree, orbit.breakpoints)).
Eigen::VectorXd orbit_value(const PeriodicMesh& mesh, const Eigen::MatrixXd& profile, double s);

}  // namespace ddemap
