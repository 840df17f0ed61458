// The progress callback of the root backends (RootOptions::progress) and its cancellation: one
// call per unit of work (contour counts, Arnoldi shifts and their steps, dense degrees, counted independently by
// the result's own counters), and a callback that throws ddemap::Cancelled stops the work with
// Status::Cancelled, no roots and an undecided verdict (how Ctrl-C stops roots --system and
// mixed_ring from Python); any other exception reaches the caller as it is.
#include <doctest/doctest.h>

#include <complex>
#include <stdexcept>
#include <vector>

#include <Eigen/Eigenvalues>

#include "ddemap/analysis/stability/mixed_ring.hpp"
#include "ddemap/analysis/stability/ring_stability.hpp"
#include "ddemap/discretize/collocation.hpp"
#include "ddemap/solve/roots.hpp"
#include "ddemap/traffic/ring.hpp"
#include "fleet_helpers.hpp"
#include "ddemap/analysis/stability/system_roots.hpp"
#include "ddemap/traffic/fleet.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;

namespace {

struct Seen {
    std::vector<long> done, total;
};

/// Records every call; throws Cancelled at the call number `stop_at` (never when 0).
BranchProgress recorder(Seen& seen, long stop_at = 0) {
    return [&seen, stop_at](long done, long total, double) {
        seen.done.push_back(done);
        seen.total.push_back(total);
        if (static_cast<long>(seen.done.size()) == stop_at) throw Cancelled();
    };
}

MixedRingOptions ring_options(const std::string& method) {
    MixedRingOptions o;
    o.speed = 20.0;
    o.roots.method = method;
    o.roots.count = 6;
    return o;
}

}  // namespace

TEST_CASE("mixed ring, product path: one progress call per contour count, Cancelled gives Status::Cancelled") {
    const Fleet fleet = fleet_from_pattern("A_min,C_max", 60);
    MixedRingOptions o = ring_options("contour");
    const MixedRingResult plain = analyse_mixed_ring(fleet, o);
    REQUIRE(plain.roots.status == Status::Converged);
    Seen seen;
    o.roots.progress = recorder(seen);
    const MixedRingResult watched = analyse_mixed_ring(fleet, o);
    // the callback changes nothing, and is called once per count the result reports
    CHECK(watched.roots.status == Status::Converged);
    REQUIRE(watched.roots.roots.size() == plain.roots.roots.size());
    for (std::size_t i = 0; i < plain.roots.roots.size(); ++i) CHECK(watched.roots.roots[i].value == plain.roots.roots[i].value);
    CHECK(static_cast<long>(seen.done.size()) == watched.roots.contour_counts);
    for (std::size_t i = 0; i < seen.done.size(); ++i) {
        CHECK(seen.done[i] == static_cast<long>(i + 1));
        CHECK(seen.total[i] == o.roots.contour.max_cells);
    }
    // cancelled at the third count: no roots, undecided, the status says so
    Seen stopped;
    o.roots.progress = recorder(stopped, 3);
    const MixedRingResult cancelled = analyse_mixed_ring(fleet, o);
    CHECK(stopped.done.size() == 3);
    CHECK(cancelled.roots.status == Status::Cancelled);
    CHECK(to_string(cancelled.roots.status) == "cancelled");
    CHECK(cancelled.roots.roots.empty());
    CHECK(cancelled.verdict == Verdict::Undecided);
    CHECK_FALSE(cancelled.stable);
    CHECK(cancelled.roots.message.find("cancelled") != std::string::npos);
}

TEST_CASE("mixed ring, sparse path: a progress call per Arnoldi shift and step, Cancelled gives Status::Cancelled") {
    const Fleet fleet = fleet_from_pattern("A_min,C_max", 20);
    MixedRingOptions o = ring_options("shift_invert");
    Seen seen;
    o.roots.progress = recorder(seen);
    const MixedRingResult r = analyse_mixed_ring(fleet, o);
    REQUIRE(r.roots.status == Status::Converged);
    // each shift reports the shifts done before it, then again (the same count) after every
    // Arnoldi step within it, and each resolvent test between shifts the shifts done: the counts
    // never decrease and take every value 0 .. shifts - 1 (and shifts, after the last one)
    std::vector<long> distinct;
    for (std::size_t i = 0; i < seen.done.size(); ++i) {
        if (i > 0) CHECK(seen.done[i] >= seen.done[i - 1]);
        if (distinct.empty() || distinct.back() != seen.done[i]) distinct.push_back(seen.done[i]);
    }
    CHECK(static_cast<long>(distinct.size()) >= r.roots.shifts);
    CHECK(static_cast<long>(distinct.size()) <= r.roots.shifts + 1);
    for (std::size_t i = 0; i < distinct.size(); ++i) CHECK(distinct[i] == static_cast<long>(i));
    CHECK(static_cast<long>(seen.done.size()) >= r.roots.shifts + r.roots.arnoldi_steps);
    REQUIRE(r.roots.shifts >= 1);
    // cancelled within the last shift's Arnoldi steps
    const long last = static_cast<long>(seen.done.size());
    Seen stopped;
    o.roots.progress = recorder(stopped, last);
    const MixedRingResult cancelled = analyse_mixed_ring(fleet, o);
    CHECK(static_cast<long>(stopped.done.size()) == last);
    CHECK(cancelled.roots.status == Status::Cancelled);
    CHECK(cancelled.roots.roots.empty());
    CHECK(cancelled.verdict == Verdict::Undecided);
}

TEST_CASE("system roots, dense path: a progress call per degree, Cancelled gives Status::Cancelled, other exceptions pass") {
    // x' = -x(t - 1): the dense path raises M until the roots settle
    const LinearDDE dde(MatrixXc::Zero(1, 1), {{MatrixXc::Constant(1, 1, -1.0), 1.0}});
    RootOptions o;
    o.method = "dense";
    Seen seen;
    o.progress = recorder(seen);
    const SystemRootResult r = analyse_system(dde, o);
    REQUIRE(r.roots.status == Status::Converged);
    REQUIRE(!seen.done.empty());
    CHECK(seen.done.back() == r.roots.degree);  // the last call reports the degree used
    CHECK(seen.total.back() == o.dense.max_degree);
    Seen stopped;
    o.progress = recorder(stopped, 1);
    const SystemRootResult cancelled = analyse_system(dde, o);
    CHECK(cancelled.roots.status == Status::Cancelled);
    CHECK(cancelled.roots.roots.empty());
    CHECK(cancelled.verdict == Verdict::Undecided);
    CHECK_FALSE(cancelled.stable);
    o.progress = [](long, long, double) { throw std::runtime_error("not a cancellation"); };
    CHECK_THROWS_AS(analyse_system(dde, o), std::runtime_error);
}

TEST_CASE("dense eigenvalues in stages: Eigen's values in one piece, checks between the stages, and a throwing check stops them") {
    // a complex mode of the infinite ring (theta = 1) at degree 120: a 242-state complex eigenvalue problem
    const Linearisation lin = test::ovrv(0.2, 0.2, 1.5, 0.1);
    const LinearDDE dde = ring_mode_dde(lin, std::polar(1.0, -1.0));
    const Eigen::ComplexEigenSolver<MatrixXc> whole(collocation_matrix(dde, 120), false);
    REQUIRE(whole.info() == Eigen::Success);
    long calls = 0;
    std::vector<cplx> staged;
    REQUIRE(collocation_eigenvalues(dde, 120, staged, [&] { ++calls; }));
    // the reduction is Eigen's step for step and the QR steps resume from Eigen's own partial
    // result: the same values in the same order
    REQUIRE(staged.size() == static_cast<std::size_t>(whole.eigenvalues().size()));
    for (std::size_t i = 0; i < staged.size(); ++i) CHECK(staged[i] == whole.eigenvalues()[static_cast<Eigen::Index>(i)]);
    CHECK(calls >= 241 / 16);  // every 16 Householder columns at least
    long stopped = 0;
    CHECK_THROWS_AS(collocation_eigenvalues(dde, 120, staged, [&] {
                        if (++stopped == 3) throw Cancelled();
                    }),
                    Cancelled);
    CHECK(stopped == 3);
    // a small problem (82 states) is one piece
    calls = 0;
    REQUIRE(collocation_eigenvalues(dde, 40, staged, [&] { ++calls; }));
    CHECK(calls == 0);
}

TEST_CASE("ring N = inf: the search stopped within its one long dense degree stops the ring (Cancelled reaches the caller)") {
    // near the edge of the computable range the search for 5 roots at the abscissa's wave number
    // climbs from M = 22 to M = 400 in one degree (802 complex states, seconds); its progress is
    // called within that degree with the last report repeated
    const Linearisation lin = test::ovrv(19, 0.2, 1.5, 0.2);
    RingOptions o;
    o.roots.count = 5;
    std::vector<long> done;
    o.roots.progress = [&](long d, long, double) {
        const bool repeated = !done.empty() && done.back() == d;
        done.push_back(d);
        if (repeated) throw Cancelled();
    };
    CHECK_THROWS_AS(analyse_ring(lin, 0, o), Cancelled);
    REQUIRE(done.size() == 2);
    CHECK(done[0] > 0);  // the first degree finished, then a call from within the next one
}

TEST_CASE("estimate_root_work: the predicted shifts of a ring against the run's, and the before callback refuses before any work") {
    // a ring's shifts grow like 1.2 sqrt(n) (n = 2 N states): the prediction is within a factor
    // of 1.6 of the shifts the search then takes (16 at 200 cars, 54 at 1000: BENCHMARKS.md)
    for (int cars : {200, 1000}) {
        CAPTURE(cars);
        const Fleet fleet = fleet_from_pattern("A_min,B_min", cars);
        MixedRingOptions o = ring_options("shift_invert");
        RootWorkEstimate seen;
        int calls = 0;
        o.roots.before = [&seen, &calls](const RootWorkEstimate& e) {
            seen = e;
            ++calls;
        };
        const MixedRingResult r = analyse_mixed_ring(fleet, o);
        REQUIRE(r.roots.status == Status::Converged);
        CHECK(calls == 1);
        CHECK(seen.method == "shift_invert");
        CHECK(seen.units <= 1.6 * r.roots.shifts);
        CHECK(seen.units >= r.roots.shifts / 1.6);
        CHECK(seen.seconds > 0.0);
        CHECK(seen.bytes > 0.0);
        CHECK(seen.basis.find("Arnoldi shifts") != std::string::npos);
    }
    // the callback throws: nothing else runs (no progress call), the exception reaches the caller
    const Fleet fleet = fleet_from_pattern("A_min,B_min", 200);
    MixedRingOptions o = ring_options("shift_invert");
    Seen seen;
    o.roots.progress = recorder(seen);
    o.roots.before = [](const RootWorkEstimate&) { throw std::invalid_argument("too large"); };
    CHECK_THROWS_WITH_AS(analyse_mixed_ring(fleet, o), "too large", std::invalid_argument);
    CHECK(seen.done.empty());
    // the method is the one the facade would choose
    o.roots.method = "auto";
    o.roots.before = nullptr;
    const RootProblem p{LinearDDE(MatrixXc::Zero(1, 1), {{MatrixXc::Constant(1, 1, -1.0), 1.0}}), nullptr};
    RootOptions ro;
    CHECK(estimate_root_work(p, ro).method == choose_root_method(p, ro));
    CHECK(estimate_root_work(p, ro).method == "dense");
    ro.shift_invert.expected_shifts = -1.0;
    CHECK_THROWS_AS(estimate_root_work(p, ro), std::invalid_argument);
}
