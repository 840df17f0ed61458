#include "format.hpp"

#include <cstdio>

namespace ddemap::cli {

std::string rounded(double v, int digits) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*g", digits, v == 0.0 ? 0.0 : v);
    return buf;
}

std::string roots_table(const std::vector<Root>& roots) {
    // units in the header (a growth rate in 1/s, an angular frequency in rad/s; the residual is
    // relative, no unit)
    std::string out = "  #          re [1/s]        im [rad/s]    residual\n";
    int i = 0;
    for (const auto& x : roots) {
        char line[160];
        std::snprintf(line, sizeof line, "%3d %17.12f %18.12f %11.2e\n", ++i, x.value.real(), x.value.imag(), x.residual);
        out += line;
    }
    return out;
}

}  // namespace ddemap::cli
