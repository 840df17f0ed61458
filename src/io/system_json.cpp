#include "ddemap/io/system_json.hpp"
#include <cstring>
#include <cctype>
#include <algorithm>

#include <cmath>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "core/internal/text.hpp"

namespace ddemap {

namespace {

using json = nlohmann::json;

/// A field name may be a key of the file (any characters): escaped so that the message stays one line.
[[noreturn]] void fail(const std::string& source, const std::string& field, const std::string& what) {
    throw std::invalid_argument(source + ": " + detail::escaped(field, 80) + ": " + what);
}

/// The documented coefficient range (README "--system"): 0 or a magnitude from 1e-100 to 1e100.
/// Beyond it the eigenvalue solvers lose every digit (1e300 next to 1e-300 made the Schur
/// decomposition fail), so such a file is bad input.
void check_range(double x, const std::string& source, const std::string& field) {
    const double a = std::abs(x);
    if (!std::isfinite(x) || (a != 0.0 && (a < 1e-100 || a > 1e100))) {
        fail(source, field, detail::format_number(x) + ": expected 0 or a finite magnitude from 1e-100 to 1e100");
    }
}

cplx value_of(const json& v, const std::string& source, const std::string& field) {
    if (v.is_number()) {
        const double x = v.get<double>();
        check_range(x, source, field);
        return x;
    }
    if (v.is_array() && v.size() == 2 && v[0].is_number() && v[1].is_number()) {
        const double re = v[0].get<double>(), im = v[1].get<double>();
        check_range(re, source, field + "[0]");
        check_range(im, source, field + "[1]");
        return {re, im};
    }
    fail(source, field, "expected a number or [re, im]");
}

/// The entries of a {"triplets": ...} matrix, checked (indices 0-based, values in range).
std::vector<Eigen::Triplet<cplx>> triplets_of(const json& m, int n, const std::string& source, const std::string& field) {
    if (!m.contains("triplets") || !m["triplets"].is_array()) fail(source, field, "expected {\"triplets\": [[row, col, value], ...]}");
    const json& t = m["triplets"];
    std::vector<Eigen::Triplet<cplx>> out;
    out.reserve(t.size());
    for (std::size_t i = 0; i < t.size(); ++i) {
        const std::string f = field + ".triplets[" + std::to_string(i) + "]";
        if (!t[i].is_array() || t[i].size() != 3 || !t[i][0].is_number_integer() || !t[i][1].is_number_integer()) {
            fail(source, f, "expected [row, col, value] with integer row and col");
        }
        const long r = t[i][0].get<long>(), c = t[i][1].get<long>();
        if (r < 0 || r >= n || c < 0 || c >= n) {
            fail(source, f, "index (" + std::to_string(r) + ", " + std::to_string(c) + ") outside 0.." + std::to_string(n - 1));
        }
        out.emplace_back(static_cast<int>(r), static_cast<int>(c), value_of(t[i][2], source, f));
    }
    return out;
}

MatrixXc matrix_of(const json& m, int n, const std::string& source, const std::string& field) {
    MatrixXc a = MatrixXc::Zero(n, n);
    if (m.is_object()) {
        for (const auto& t : triplets_of(m, n, source, field)) a(t.row(), t.col()) += t.value();
        return a;
    }
    if (!m.is_array() || static_cast<int>(m.size()) != n) fail(source, field, "expected " + std::to_string(n) + " rows or {\"triplets\": ...}");
    for (int r = 0; r < n; ++r) {
        const std::string fr = field + "[" + std::to_string(r) + "]";
        if (!m[r].is_array() || static_cast<int>(m[r].size()) != n) fail(source, fr, "expected " + std::to_string(n) + " entries");
        for (int c = 0; c < n; ++c) a(r, c) = value_of(m[r][c], source, fr + "[" + std::to_string(c) + "]");
    }
    return a;
}

/// Every matrix of the file given as triplets (A0 may be absent): such a file can be held sparse.
bool all_triplets(const json& j) {
    if (j.contains("A0") && !j["A0"].is_object()) return false;
    if (!j.contains("A") || !j["A"].is_array()) return false;
    for (const auto& m : j["A"])
        if (!m.is_object()) return false;
    return true;
}

/// A triplet matrix as sparse real storage; false (nothing written) when a value is complex.
bool real_sparse_of(const std::vector<Eigen::Triplet<cplx>>& t, int n, SparseMatrixXd& out) {
    std::vector<Eigen::Triplet<double>> real;
    real.reserve(t.size());
    for (const auto& e : t) {
        if (e.value().imag() != 0.0) return false;
        real.emplace_back(e.row(), e.col(), e.value().real());
    }
    out.resize(n, n);
    out.setFromTriplets(real.begin(), real.end());  // repeated entries add up
    return true;
}

}  // namespace

std::optional<LinearDdeShape> quick_peek_linear_dde_json(const std::string& text) {
    if (text.find("\"triplets\"") != std::string::npos || text.find("\"equations\"") != std::string::npos) return std::nullopt;
    auto after_key = [&](const char* key) -> std::size_t {  // the position after "KEY" and its colon
        std::size_t k = text.find(key);
        if (k == std::string::npos) return k;
        k += std::strlen(key);
        while (k < text.size() && std::isspace(static_cast<unsigned char>(text[k]))) ++k;
        if (k >= text.size() || text[k] != ':') return std::string::npos;
        ++k;
        while (k < text.size() && std::isspace(static_cast<unsigned char>(text[k]))) ++k;
        return k;
    };
    LinearDdeShape s;
    const std::size_t d = after_key("\"dimension\"");
    if (d == std::string::npos) return std::nullopt;
    std::size_t e = d;
    while (e < text.size() && e - d < 12 && std::isdigit(static_cast<unsigned char>(text[e]))) ++e;
    if (e == d || e - d >= 12) return std::nullopt;
    s.dimension = std::stol(text.substr(d, e - d));
    const std::size_t l = after_key("\"delays\"");
    if (l == std::string::npos || text[l] != '[') return std::nullopt;
    const std::size_t r = text.find(']', l);
    if (r == std::string::npos || r - l > 1000000) return std::nullopt;
    const std::string list = text.substr(l + 1, r - l - 1);
    if (list.find_first_not_of(" \t\r\n") == std::string::npos) s.delays = 0;
    else s.delays = static_cast<std::size_t>(std::count(list.begin(), list.end(), ',')) + 1;
    return s;
}

LinearDdeShape peek_linear_dde_json(const std::string& text, const std::string& source) {
    json j;
    try {
        j = json::parse(text, [](int depth, json::parse_event_t, json&) { return depth <= 2; });
    } catch (const json::parse_error& e) {
        throw std::invalid_argument(source + ": not valid JSON (" + std::string(e.what()) + ")");
    } catch (const json::out_of_range& e) {
        throw std::invalid_argument(source + ": a number outside the range of doubles (" + std::string(e.what()) + ")");
    }
    LinearDdeShape s;
    if (!j.is_object()) return s;
    if (j.contains("dimension") && j["dimension"].is_number_integer()) s.dimension = j["dimension"].get<long>();
    if (j.contains("delays") && j["delays"].is_array()) s.delays = j["delays"].size();
    if (all_triplets(j)) {
        // triplet matrices: the text is as long as the nonzeros, so reading it all is cheap
        const json full = json::parse(text, nullptr, false);
        if (full.is_discarded()) return s;
        bool real = true;
        long nonzeros = 0;
        auto scan = [&](const json& m) {
            if (!m.contains("triplets") || !m["triplets"].is_array()) return;
            for (const auto& t : m["triplets"]) {
                ++nonzeros;
                if (t.is_array() && t.size() == 3 && !t[2].is_number()) real = false;
            }
        };
        if (full.contains("A0")) scan(full["A0"]);
        for (const auto& m : full["A"]) scan(m);
        s.sparse = real;
        s.nonzeros = nonzeros;
    }
    return s;
}

LinearDDE read_linear_dde_json(const std::string& text, const std::string& source) {
    json j;
    try {
        j = json::parse(text);
    } catch (const json::parse_error& e) {
        throw std::invalid_argument(source + ": not valid JSON (" + std::string(e.what()) + ")");
    } catch (const json::out_of_range& e) {
        // e.g. 1e400: a number outside the double range is bad input, not an internal error
        throw std::invalid_argument(source + ": a number outside the range of doubles (" + std::string(e.what()) + ")");
    }
    if (!j.is_object()) fail(source, "top level", "expected an object with dimension, delays, A0, A");
    for (auto it = j.begin(); it != j.end(); ++it) {
        if (it.key() != "dimension" && it.key() != "delays" && it.key() != "A0" && it.key() != "A" && it.key() != "comment") {
            fail(source, it.key(), "unknown field (expected dimension, delays, A0, A, comment)");
        }
    }
    if (!j.contains("dimension") || !j["dimension"].is_number_integer() || j["dimension"].get<long>() < 1 ||
        j["dimension"].get<long>() > 20000) {
        fail(source, "dimension", "expected an integer from 1 to 20000");
    }
    const int n = j["dimension"].get<int>();
    std::vector<double> delays;
    if (j.contains("delays")) {
        if (!j["delays"].is_array()) fail(source, "delays", "expected an array of delays [s]");
        for (std::size_t k = 0; k < j["delays"].size(); ++k) {
            const json& d = j["delays"][k];
            const std::string f = "delays[" + std::to_string(k) + "]";
            if (!d.is_number()) fail(source, f, "expected a number");
            const double x = d.get<double>();
            if (!std::isfinite(x) || x < 0.0) fail(source, f, detail::format_number(x) + ": expected a finite delay >= 0");
            if (x > 1e100) fail(source, f, detail::format_number(x) + ": expected a delay of at most 1e100");
            delays.push_back(x);
        }
    }
    const std::size_t given = j.contains("A") ? (j["A"].is_array() ? j["A"].size() : std::size_t(-1)) : 0;
    if (given != delays.size()) {
        fail(source, "A", "expected an array of " + std::to_string(delays.size()) + " matrices, one per delay");
    }
    if (all_triplets(j)) {
        // real triplets are held sparse (large systems); a complex value makes the file dense
        SparseMatrixXd sa0(n, n);
        bool real = !j.contains("A0") || real_sparse_of(triplets_of(j["A0"], n, source, "A0"), n, sa0);
        std::vector<SparseDelayTerm> sterms;
        for (std::size_t k = 0; real && k < delays.size(); ++k) {
            SparseMatrixXd a;
            real = real_sparse_of(triplets_of(j["A"][k], n, source, "A[" + std::to_string(k) + "]"), n, a);
            sterms.push_back({a, delays[k]});
        }
        if (real) return LinearDDE(sa0, sterms);
    }
    const MatrixXc a0 = j.contains("A0") ? matrix_of(j["A0"], n, source, "A0") : MatrixXc::Zero(n, n);
    std::vector<DelayTerm> terms;
    for (std::size_t k = 0; k < delays.size(); ++k) {
        terms.push_back({matrix_of(j["A"][k], n, source, "A[" + std::to_string(k) + "]"), delays[k]});
    }
    return LinearDDE(a0, terms);
}

bool is_nonlinear_system_json(const std::string& text) {
    // a text search first (a linear file of 500 MB was parsed whole here, 1 GB of memory);
    // then only the top level is kept
    if (text.find("\"equations\"") == std::string::npos) return false;
    const nlohmann::ordered_json j =
        nlohmann::ordered_json::parse(text, [](int depth, nlohmann::ordered_json::parse_event_t, nlohmann::ordered_json&) { return depth <= 1; }, false);
    return !j.is_discarded() && j.is_object() && j.contains("equations");
}

NonlinearSystemFile read_nonlinear_system_json(const std::string& text, const std::string& source) {
    using ojson = nlohmann::ordered_json;
    ojson j;
    try {
        j = ojson::parse(text);
    } catch (const ojson::parse_error& e) {
        throw std::invalid_argument(source + ": not valid JSON (" + std::string(e.what()) + ")");
    } catch (const ojson::out_of_range& e) {
        throw std::invalid_argument(source + ": a number outside the range of doubles (" + std::string(e.what()) + ")");
    }
    if (!j.is_object()) fail(source, "top level", "expected an object with variables, parameters, equations");
    for (auto it = j.begin(); it != j.end(); ++it) {
        const std::string& k = it.key();
        if (k != "variables" && k != "parameters" && k != "equations" && k != "equilibrium" && k != "comment")
            fail(source, k, "unknown field (expected variables, parameters, equations, equilibrium, comment)");
    }
    auto strings = [&](const char* field) {
        std::vector<std::string> out;
        if (!j.contains(field) || !j[field].is_array()) fail(source, field, "expected an array of strings");
        for (std::size_t i = 0; i < j[field].size(); ++i) {
            if (!j[field][i].is_string()) fail(source, std::string(field) + "[" + std::to_string(i) + "]", "expected a string");
            out.push_back(j[field][i].get<std::string>());
        }
        return out;
    };
    const std::vector<std::string> variables = strings("variables");
    if (variables.empty() || variables.size() > 10000) fail(source, "variables", "expected 1 to 10000 names");
    const std::vector<std::string> equations = strings("equations");
    if (equations.size() != variables.size())
        fail(source, "equations", std::to_string(equations.size()) + " equations for " + std::to_string(variables.size()) +
                                      " variables: expected one equation per variable");
    std::vector<std::string> names;
    std::vector<double> values;
    if (j.contains("parameters")) {
        if (!j["parameters"].is_object()) fail(source, "parameters", "expected an object {\"name\": value, ...}");
        for (auto it = j["parameters"].begin(); it != j["parameters"].end(); ++it) {
            if (!it.value().is_number()) fail(source, "parameters." + it.key(), "expected a number");
            const double v = it.value().get<double>();
            if (!std::isfinite(v)) fail(source, "parameters." + it.key(), "expected a finite number");
            // a subnormal parameter (a delay of 1e-320) overflows 1 / tau: the coefficients' range
            if (v != 0.0 && (std::abs(v) < 1e-100 || std::abs(v) > 1e100))
                fail(source, "parameters." + it.key(), detail::format_number(v) + ": expected 0 or a finite magnitude from 1e-100 to 1e100");
            names.push_back(it.key());
            values.push_back(v);
        }
    }
    NonlinearSystemFile out;
    try {
        out.system = std::make_shared<ExpressionSystem>(variables, names, values, equations);
    } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(source + ": " + detail::escaped(e.what(), 400));
    }
    // a delay written as a number in an equation (x(t - 1e308)) has the range of a linear file's
    // delays: at most 1e100 (beyond, 1 / tau is subnormal and the dense eigenvalues crawl)
    {
        std::vector<double> tau;
        try {
            tau = out.system->delays();
        } catch (const std::invalid_argument&) {
            tau.clear();  // a delay that cannot be evaluated at the file's values: reported where it is used
        }
        for (const double t : tau)
            if (std::isfinite(t) && t > 1e100) fail(source, "equations", "a delay of " + detail::format_number(t) + ": expected a delay of at most 1e100");
    }
    const std::size_t n = variables.size();
    out.equilibrium = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n));
    if (j.contains("equilibrium")) {
        const ojson& e = j["equilibrium"];
        if (!e.is_array() || e.size() != n) fail(source, "equilibrium", "expected an array of " + std::to_string(n) + " numbers (one per variable)");
        for (std::size_t i = 0; i < n; ++i) {
            const std::string f = "equilibrium[" + std::to_string(i) + "]";
            if (!e[i].is_number()) fail(source, f, "expected a number");
            const double v = e[i].get<double>();
            if (!std::isfinite(v)) fail(source, f, "expected a finite number");
            out.equilibrium[static_cast<Eigen::Index>(i)] = v;
        }
        out.equilibrium_given = true;
    }
    return out;
}

}  // namespace ddemap
