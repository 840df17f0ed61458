#include <doctest/doctest.h>

#include "ddemap/problem/expoly.hpp"

TEST_SUITE_BEGIN("fast");

using ddemap::ExpPoly;

TEST_CASE("ExpPoly equality: the same terms after merging, and nothing else") {
    ExpPoly a, b, c, d;
    a.add(0.5, 0.2).add(-1.0, 0.0);
    b.add(-1.0, 0.0).add(0.25, 0.2).add(0.25, 0.2);  // merged into the same two terms
    c.add(0.5, 0.2).add(-1.0, 0.1);                  // another delay
    d.add(0.5, 0.2);                                  // fewer terms
    CHECK(a == a);
    CHECK(a == b);
    CHECK(a != c);
    CHECK(a != d);
    CHECK(ExpPoly() == ExpPoly());
}

TEST_SUITE_END();
