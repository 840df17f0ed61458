#pragma once
// Options of a two-parameter curve (Hopf curves, fold curves) for the box [from, to] x [from2, to2]
// in (p1, p2), the rest by default.
#include <string>

#include "ddemap/analysis/bifurcation/equilibrium_branch.hpp"

namespace ddemap::test {

template <class Options>
Options two_parameter_box(const std::string& p1, double from, double to, const std::string& p2, double from2, double to2) {
    Options o;
    o.branch.parameter = p1;
    o.branch.from = from;
    o.branch.to = to;
    o.parameter2 = p2;
    o.from2 = from2;
    o.to2 = to2;
    return o;
}

}  // namespace ddemap::test
