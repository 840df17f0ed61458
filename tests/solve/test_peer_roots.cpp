// Rightmost roots against values published with a peer's tool (TDS-CONTROL, KU Leuven): the
// systems of its manual's examples, the values as the Python port tdcpy's tests state them.
#include <doctest/doctest.h>

#include <cmath>

#include "ddemap/solve/roots.hpp"
#include "tolerances.hpp"

TEST_SUITE_BEGIN("reference");

using namespace ddemap;
namespace tol = ddemap::test::tol;

TEST_CASE("TDS-CONTROL manual example 2.1: the rightmost root is real, 0.6176424667764324, on every backend that applies") {
    // x'(t) = A0 x(t) + A1 x(t - 1), 4 states (TDS-CONTROL manual, section 2.1)
    MatrixXc A0(4, 4), A1(4, 4);
    A0 << -1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -10, -4, 0, 0, 4, -10;
    A1 << 3, 3, 3, 3, 0, -1.5, 0, 0, 0, 0, 3, -5, 0, 5, 5, 5;
    const LinearDDE dde(A0, {{A1, 1.0}});
    for (const char* method : {"dense", "shift_invert"}) {
        CAPTURE(method);
        RootOptions o;
        o.method = method;
        o.count = 3;
        const RootResult r = rightmost_roots(dde, o);
        REQUIRE(r.status == Status::Converged);
        REQUIRE(!r.roots.empty());
        const cplx top = r.roots.front().value;
        // the peer prints 16 digits computed from its own discretisation, corrected by Newton
        CHECK(std::abs(top.real() - 0.6176424667764324) < tol::peer_root);
        CHECK(std::abs(top.imag()) < tol::peer_root);
    }
}

TEST_SUITE_END();
