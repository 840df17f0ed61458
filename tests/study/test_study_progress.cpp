// The progress callbacks of the penetration study (mix), the disturbance growth study (growth)
// and the travelling-wave branch (orbits --wave): one call per finished unit, counted against the
// result's own counts; the callback changes nothing; and cancellation: ddemap::Cancelled from
// the study's callback (or from a root search under it) gives Status::Cancelled for the units
// not finished and keeps the finished ones exactly as an uncancelled run computes them; the
// growth study's cancellation crosses no parallel region (threads = 1 and 2). The wave branch
// and the ring N = infinity follow the branches and the per-mode ring: a callback's exception
// reaches the caller.
#include <doctest/doctest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "ddemap/analysis/stability/ring_stability.hpp"
#include "ddemap/analysis/bifurcation/travelling_wave.hpp"
#include "ddemap/study/growth.hpp"
#include "ddemap/study/penetration.hpp"
#include "ddemap/traffic/fleet.hpp"
#include "ddemap/traffic/vehicles.hpp"
#include "fleet_helpers.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;

namespace {

struct Seen {
    std::vector<long> done, total;
    std::vector<double> par;
};

/// Records every call; throws Cancelled at the call number `stop_at` (never when 0).
BranchProgress recorder(Seen& seen, long stop_at = 0) {
    return [&seen, stop_at](long done, long total, double par) {
        seen.done.push_back(done);
        seen.total.push_back(total);
        seen.par.push_back(par);
        if (static_cast<long>(seen.done.size()) == stop_at) throw Cancelled();
    };
}

MixOptions mix_options() {
    MixOptions o;
    o.cars = 20;
    o.fractions = {0.0, 0.5, 1.0};
    o.draws = 1;
    o.ring.speed = 20.0;
    o.ring.roots.method = "contour";
    o.ring.roots.count = 4;
    return o;
}

void check_same_point(const MixPoint& a, const MixPoint& b) {
    CHECK(a.fraction == b.fraction);
    CHECK(a.x_cars == b.x_cars);
    CHECK(a.abscissa == b.abscissa);
    CHECK(a.abscissa_min == b.abscissa_min);
    CHECK(a.abscissa_max == b.abscissa_max);
    CHECK(a.arrangements == b.arrangements);
    CHECK(a.stable == b.stable);
    CHECK(a.status == b.status);
}

void check_same_growth(const GrowthResult& a, const GrowthResult& b) {
    CHECK(a.name == b.name);
    CHECK(a.status == b.status);
    CHECK(a.amplification == b.amplification);
    CHECK(a.min_gap == b.min_gap);
    CHECK(a.failed_at == b.failed_at);
    CHECK(a.failure_time == b.failure_time);
}

}  // namespace

TEST_CASE("mix: one progress call per arrangement solved, and Cancelled gives Status::Cancelled for the points not complete") {
    const FleetCar x = parse_fleet_car("A_min"), y = parse_fleet_car("C_max");
    MixOptions o = mix_options();
    const std::vector<MixPoint> plain = penetration_study(x, y, o);
    REQUIRE(plain.size() == 3);
    for (const MixPoint& pt : plain) REQUIRE(pt.status == Status::Converged);
    Seen seen;
    o.progress = recorder(seen);
    const std::vector<MixPoint> watched = penetration_study(x, y, o);
    // 3 fractions x (1 + 1 draw) arrangements, counted 1..6 with their p, and the same result
    REQUIRE(seen.done.size() == 6);
    long arrangements = 0;
    for (const MixPoint& pt : watched) arrangements += pt.arrangements;
    CHECK(arrangements == 6);
    for (std::size_t i = 0; i < seen.done.size(); ++i) {
        CHECK(seen.done[i] == static_cast<long>(i + 1));
        CHECK(seen.total[i] == 6);
        CHECK(seen.par[i] == o.fractions[i / 2]);
    }
    REQUIRE(watched.size() == plain.size());
    for (std::size_t i = 0; i < plain.size(); ++i) check_same_point(watched[i], plain[i]);

    // cancelled at the third arrangement (the first of p = 0.5): p = 0 complete and unchanged,
    // p = 0.5 with one arrangement solved, p = 1 with none; both cancelled and not stable
    Seen stopped;
    o.progress = recorder(stopped, 3);
    const std::vector<MixPoint> cancelled = penetration_study(x, y, o);
    CHECK(stopped.done.size() == 3);
    REQUIRE(cancelled.size() == 3);
    check_same_point(cancelled[0], plain[0]);
    CHECK(cancelled[1].status == Status::Cancelled);
    CHECK(cancelled[1].arrangements == 1);
    CHECK_FALSE(cancelled[1].stable);
    CHECK(cancelled[1].abscissa == plain[1].abscissa);  // the spread arrangement was solved
    CHECK(cancelled[2].status == Status::Cancelled);
    CHECK(cancelled[2].arrangements == 0);
    CHECK_FALSE(cancelled[2].stable);
    CHECK(cancelled[2].fraction == 1.0);
    CHECK(to_string(cancelled[2].status) == "cancelled");
}

TEST_CASE("mix: a root search cancelled through ring.roots.progress stops the study the same way") {
    const FleetCar x = parse_fleet_car("A_min"), y = parse_fleet_car("C_max");
    MixOptions o = mix_options();
    Seen outer, inner;
    o.progress = recorder(outer);
    // the root search's fifth contour count over the whole study throws
    long counts = 0;
    o.ring.roots.progress = [&](long done, long total, double par) {
        inner.done.push_back(done);
        inner.total.push_back(total);
        inner.par.push_back(par);
        if (++counts == 5) throw Cancelled();
    };
    const std::vector<MixPoint> r = penetration_study(x, y, o);
    REQUIRE(r.size() == 3);
    CHECK(counts == 5);
    // every point is cancelled or complete, and those reported as solved are the complete ones
    long solved = 0;
    for (const MixPoint& pt : r) {
        if (pt.status == Status::Converged) CHECK(pt.arrangements == o.draws + 1);
        else CHECK(pt.status == Status::Cancelled);
        solved += pt.arrangements;
    }
    CHECK(static_cast<long>(outer.done.size()) == solved);
    CHECK(r.back().status == Status::Cancelled);
}

TEST_CASE("growth: one progress call per platoon, and Cancelled gives Status::Cancelled for the platoons not simulated (1 and 2 threads)") {
    const std::vector<CalibratedVehicle> vehicles = paper_calibration_table();
    const LeadProfile lead = LeadProfile::builtin("dip");
    const std::vector<GrowthResult> plain = disturbance_growth(vehicles, lead, 3);
    REQUIRE(plain.size() == vehicles.size());
    for (const GrowthResult& g : plain) REQUIRE(g.status == Status::Converged);
    for (int threads : {1, 2}) {
        INFO("threads = " << threads);
        std::vector<long> done, total;
        ExecutionPolicy policy;
        policy.threads = threads;
        policy.progress = [&](long d, long t) {
            done.push_back(d);
            total.push_back(t);
        };
        const std::vector<GrowthResult> watched = disturbance_growth(vehicles, lead, 3, SimOptions{}, policy);
        REQUIRE(done.size() == vehicles.size());
        for (std::size_t i = 0; i < done.size(); ++i) {
            CHECK(done[i] == static_cast<long>(i + 1));
            CHECK(total[i] == static_cast<long>(vehicles.size()));
        }
        for (std::size_t i = 0; i < plain.size(); ++i) check_same_growth(watched[i], plain[i]);

        // the third call cancels: at least those three are simulated (as without a callback),
        // every other one is Cancelled with only its name
        long calls = 0;
        policy.progress = [&](long, long) {
            if (++calls == 3) throw Cancelled();
        };
        const std::vector<GrowthResult> cancelled = disturbance_growth(vehicles, lead, 3, SimOptions{}, policy);
        REQUIRE(cancelled.size() == vehicles.size());
        int simulated = 0, stopped = 0;
        for (std::size_t i = 0; i < cancelled.size(); ++i) {
            CHECK(cancelled[i].name == vehicles[i].name);
            if (cancelled[i].status == Status::Cancelled) {
                ++stopped;
                CHECK(cancelled[i].amplification.empty());
            } else {
                ++simulated;
                check_same_growth(cancelled[i], plain[i]);
            }
        }
        CHECK(simulated >= 3);
        CHECK(simulated <= 3 + threads - 1);  // the tasks running when it cancelled end
        CHECK(stopped == static_cast<int>(vehicles.size()) - simulated);
        if (threads == 1) CHECK(cancelled[3].status == Status::Cancelled);
    }
}

TEST_CASE("orbits --wave: one progress call per wave of the branch, and a throwing callback's exception reaches the caller" * doctest::test_suite("slow")) {
    TravellingWaveOptions o;
    o.model = "ov";
    o.cars = 3;
    o.wave = 1;
    o.orbit.parameter = "headway";
    o.orbit.from = 3.5;
    o.orbit.to = 2.0;
    o.orbit.intervals = 20;
    o.orbit.max_points = 6;
    o.orbit.floquet = false;
    Seen seen;
    o.orbit.progress = recorder(seen);
    const TravellingWaveBranch w = travelling_wave_branch({}, o);
    REQUIRE(w.branch.status == Status::Converged);
    REQUIRE(!w.branch.points.empty());
    REQUIRE(seen.done.size() == w.branch.points.size());
    for (std::size_t i = 0; i < seen.done.size(); ++i) {
        CHECK(seen.done[i] == static_cast<long>(i + 1));
        CHECK(seen.total[i] == o.orbit.max_points);
        CHECK(seen.par[i] == w.branch.points[i].par);
    }
    // stopped at the second wave: the exception reaches the caller (no partial branch)
    struct Stop : std::runtime_error {
        Stop() : std::runtime_error("stopped by the caller") {}
    };
    long calls = 0;
    o.orbit.progress = [&](long, long, double) {
        if (++calls == 2) throw Stop();
    };
    CHECK_THROWS_AS(travelling_wave_branch({}, o), Stop);
    CHECK(calls == 2);
}

TEST_CASE("ring N = infinity: one progress call per wave number solved, ending at done == total, and a throwing callback stops it") {
    const Linearisation lin = test::ovrv(0.2, 0.2, 1.5, 0.1);  // the paper's example
    RingOptions o;
    o.roots.count = 3;
    const RingResult plain = analyse_ring(lin, 0, o);
    REQUIRE(plain.status == Status::Converged);
    std::vector<long> done, total;
    o.progress = [&](long d, long t) {
        done.push_back(d);
        total.push_back(t);
    };
    const RingResult watched = analyse_ring(lin, 0, o);
    CHECK(watched.spectral_abscissa == plain.spectral_abscissa);
    // every wave-number problem solved is reported (the result counts them on its own)
    // (modes_solved also counts the search for the --count roots when it settled; that search
    // reports its own steps)
    const bool settled = watched.reason.find("did not settle") == std::string::npos;
    REQUIRE(static_cast<long>(done.size()) == watched.modes_solved - (settled ? 1 : 0));
    const long bound = o.theta_grid + 13 + 43;  // the documented bound
    for (std::size_t i = 0; i < done.size(); ++i) {
        CHECK(done[i] == static_cast<long>(i + 1));
        CHECK(total[i] >= done[i]);
        CHECK(total[i] <= bound);
        if (i > 0) CHECK(total[i] <= total[i - 1]);  // the bound only comes down
    }
    CHECK(total.back() == done.back());
    // the search for the --count roots reports through roots.progress, the scan's searches do not
    long steps = 0;
    o.roots.progress = [&](long, long, double) { ++steps; };
    o.roots.count = 1;  // no such search
    analyse_ring(lin, 0, o);
    CHECK(steps == 0);
    o.roots.count = 3;
    analyse_ring(lin, 0, o);
    CHECK(steps >= 1);
    struct Stop : std::runtime_error {
        Stop() : std::runtime_error("stopped by the caller") {}
    };
    long calls = 0;
    o.progress = [&](long, long) {
        if (++calls == 10) throw Stop();
    };
    CHECK_THROWS_AS(analyse_ring(lin, 0, o), Stop);
    CHECK(calls == 10);
}

TEST_SUITE_END();
