#include "ddemap/core/units.hpp"

#include <cctype>

namespace ddemap {

std::string unit_suffix(const std::string& unit) {
    if (unit.empty() || unit == "1" || unit == "-") return "";
    if (unit == "m/s") return "_mps";
    if (unit == "m/s^2") return "_mps2";
    std::string u = unit;
    if (u.rfind("1/", 0) == 0) u = "per_" + u.substr(2);
    std::string out = "_";
    for (std::size_t i = 0; i < u.size(); ++i) {
        const char c = u[i];
        if (c == '/') out += "_per_";
        else if (c == '^') continue;
        else if (std::isalnum(static_cast<unsigned char>(c))) out += c;
        else if (out.back() != '_') out += '_';
    }
    while (out.size() > 1 && out.back() == '_') out.pop_back();
    return out == "_" ? std::string() : out;
}

std::string column_name(const std::string& name, const std::string& unit) { return name + unit_suffix(unit); }

std::string strip_unit(const std::string& column, const std::string& unit) {
    const std::string s = unit_suffix(unit);
    if (s.empty() || column.size() <= s.size() || column.compare(column.size() - s.size(), s.size(), s) != 0) return column;
    return column.substr(0, column.size() - s.size());
}

}  // namespace ddemap
