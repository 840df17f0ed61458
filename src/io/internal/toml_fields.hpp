#pragma once
// Strict TOML fields of the spec files (chart and atlas specs): one-line errors naming the
// source, the line and the key; numbers finite; integers TOML integers in range (not a float
// such as 1e308, which toml++ would convert with undefined behaviour).
#include <cmath>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>

#include <toml++/toml.h>

namespace ddemap::detail {

/// "SOURCE:LINE" of a node.
inline std::string toml_where(const std::string& source, const toml::node& n) {
    return source + ":" + std::to_string(n.source().begin.line);
}

/// A finite number (integer or float); std::invalid_argument naming the key otherwise.
inline double toml_number(const std::string& source, const toml::node& n, const std::string& key) {
    if (auto v = n.value<double>()) {
        if (!std::isfinite(*v)) throw std::invalid_argument(toml_where(source, n) + ": " + key + ": expected a finite number");
        return *v;
    }
    throw std::invalid_argument(toml_where(source, n) + ": " + key + ": expected a number");
}

/// A TOML integer from lo to hi; nullopt otherwise.
inline std::optional<int64_t> toml_integer_in(const toml::node& n, int64_t lo, int64_t hi) {
    if (!n.is_integer()) return std::nullopt;
    const int64_t v = n.as_integer()->get();
    if (v < lo || v > hi) return std::nullopt;
    return v;
}

}  // namespace ddemap::detail
