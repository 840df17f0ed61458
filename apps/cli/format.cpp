#include "format.hpp"

#include <cstdio>

namespace ddemap::cli {

std::string exact(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.17g", v == 0.0 ? 0.0 : v);  // no "-0"
    return buf;
}

std::string rounded(double v, int digits) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*g", digits, v == 0.0 ? 0.0 : v);
    return buf;
}

std::string csv_field(const std::string& s) {
    if (s.find_first_of(",\"\n") == std::string::npos) return s;
    std::string out = "\"";
    for (char c : s) {
        if (c == '"') out += '"';
        out += c;
    }
    return out + "\"";
}

std::string roots_csv(const std::vector<Root>& roots) {
    std::string out = "re,im,residual,newton_step\n";
    for (const auto& x : roots)
        out += exact(x.value.real()) + "," + exact(x.value.imag()) + "," + exact(x.residual) + "," + exact(x.newton_step) + "\n";
    return out;
}

std::string roots_table(const std::vector<Root>& roots) {
    std::string out = "  #                re                 im    residual\n";
    int i = 0;
    for (const auto& x : roots) {
        char line[160];
        std::snprintf(line, sizeof line, "%3d %17.12f %18.12f %11.2e\n", ++i, x.value.real(), x.value.imag(), x.residual);
        out += line;
    }
    return out;
}

}  // namespace ddemap::cli
