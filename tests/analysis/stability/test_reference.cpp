// Agreement with an independent 40-digit computation (scripts/reference_data.py: argument-
// principle counts plus multistart Newton in mpmath; no eigenvalue method, no ddemap code).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "ddemap/analysis/stability/ring_stability.hpp"
#include "ddemap/analysis/stability/string_stability.hpp"
#include "tolerances.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;
namespace tol = ddemap::test::tol;

namespace {

std::vector<std::map<std::string, std::string>> read_csv(const std::string& path) {
    std::ifstream in(path);
    REQUIRE_MESSAGE(in.good(), "cannot open " << path);
    std::string line;
    std::getline(in, line);
    std::vector<std::string> header;
    {
        std::stringstream ss(line);
        std::string f;
        while (std::getline(ss, f, ',')) header.push_back(f);
    }
    std::vector<std::map<std::string, std::string>> rows;
    while (std::getline(in, line)) {
        if (line.empty()) continue;
        std::stringstream ss(line);
        std::string f;
        std::map<std::string, std::string> row;
        for (const auto& h : header) {
            std::getline(ss, f, ',');
            row[h] = f;
        }
        rows.push_back(row);
    }
    return rows;
}

double d(const std::map<std::string, std::string>& row, const char* key) { return std::stod(row.at(key)); }

Linearisation ovrv_of(const std::map<std::string, std::string>& row) {
    return make_model("ovrv", {{"k1", d(row, "k1")}, {"k2", d(row, "k2")}, {"th", d(row, "th")}, {"tau", d(row, "tau")}})
        ->linearise();
}

}  // namespace

TEST_CASE("ring roots agree with the 40-digit reference to 1e-10 (N = 2 .. 50)" * doctest::test_suite("reference")) {
    const auto rows = read_csv(std::string(DDEMAP_TEST_DATA) + "/reference_ring_roots.csv");
    REQUIRE(rows.size() > 100);
    // group: (case, N) -> reference roots over all modes (with conjugates of modes 0 < m < N/2)
    std::map<std::pair<std::string, int>, std::vector<std::map<std::string, std::string>>> groups;
    for (const auto& r : rows) groups[{r.at("case"), std::stoi(r.at("N"))}].push_back(r);
    int compared = 0;
    for (const auto& key_group : groups) {
        const auto& key = key_group.first;  // plain variables: CAPTURE takes them in a lambda
        const auto& group = key_group.second;
        const int n = key.second;
        const Linearisation lin = ovrv_of(group.front());
        RingOptions ro;
        ro.roots.count = 6;
        const RingResult ring = analyse_ring(lin, n, ro);
        REQUIRE(ring.status == Status::Converged);
        // per mode: the reference's ranked roots equal ours
        std::map<int, std::vector<cplx>> ref_by_mode;
        std::vector<cplx> ref_all;
        for (const auto& r : group) {
            const int m = std::stoi(r.at("mode"));
            const cplx z(d(r, "re"), d(r, "im"));
            ref_by_mode[m].push_back(z);
            ref_all.push_back(z);
            if (m > 0 && 2 * m != n) ref_all.push_back(std::conj(z));
        }
        for (const auto& mode_refs : ref_by_mode) {
            const int m = mode_refs.first;  // plain variables: CAPTURE takes them in a lambda
            const std::vector<cplx>& refs = mode_refs.second;
            RootOptions o;
            o.count = static_cast<int>(refs.size()) + 2;
            const LinearDDE dde = m == 0 ? ring_mode0_dde(lin) : ring_mode_dde(lin, ring_zeta(m, n));
            const RootResult rr = rightmost_roots(dde, o);
            for (std::size_t i = 0; i < refs.size(); ++i) {
                CAPTURE(key.first);
                CAPTURE(n);
                CAPTURE(m);
                CAPTURE(i);
                REQUIRE(i < rr.roots.size());
                CAPTURE(rr.roots[i].value);
                CAPTURE(refs[i]);
                // same rank by real part; the root itself matched among ours (conjugate twins
                // of the real modes tie in the real part, so their order is not fixed)
                CHECK(std::abs(rr.roots[i].value.real() - refs[i].real()) < tol::reference_root);
                double nearest = 1e300;
                for (const auto& x : rr.roots) nearest = std::min(nearest, std::abs(x.value - refs[i]));
                CHECK(nearest < tol::reference_root);
                ++compared;
            }
        }
        // ring level: the spectral abscissa is the reference's largest real part
        double ref_abscissa = -1e300;
        for (cplx z : ref_all) ref_abscissa = std::max(ref_abscissa, z.real());
        CAPTURE(key.first);
        CAPTURE(n);
        CHECK(std::abs(ring.spectral_abscissa - ref_abscissa) < tol::reference_root);
        CHECK(ring.stable == (ref_abscissa < 0.0));
    }
    CHECK(compared > 300);
}

TEST_CASE("string verdicts and sup |Gamma| agree with the reference (1e-8 relative)") {
    const auto rows = read_csv(std::string(DDEMAP_TEST_DATA) + "/reference_string.csv");
    REQUIRE(rows.size() >= 20);
    for (const auto& row : rows) {
        CAPTURE(row.at("case"));
        const StringResult s = analyse_string(ovrv_of(row));
        const double sup = d(row, "sup_gamma"), w = d(row, "omega_peak"), pa = d(row, "plant_abscissa");
        CHECK(std::abs(s.sup_gamma - sup) <= tol::reference_sup_rel * sup);
        if (w > 0.0) {
            CHECK(std::abs(s.omega_peak - w) <= tol::reference_omega_rel * w);
        } else {
            CHECK(s.omega_peak == 0.0);
        }
        CHECK(std::abs(s.plant_abscissa - pa) < tol::reference_root);
        CHECK(s.lowfreq.c2 == doctest::Approx(d(row, "c2")).epsilon(tol::coefficient_rel).scale(1e-3));
        const bool ref_stable = pa < 0.0 && w == 0.0 && sup <= 1.0;
        CHECK(s.plant_stable == (pa < 0.0));
        CHECK(s.string_stable == ref_stable);
    }
}

TEST_SUITE_END();
