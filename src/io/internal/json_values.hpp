#pragma once
// JSON values shared by the io writers (private): a double as a number, or null when it is not
// finite (JSON has no NaN or infinity), and a vector as an array of those.
#include <cmath>
#include <string>

#include <Eigen/Core>

#include "ddemap/analysis/bifurcation/normal_forms.hpp"
#include "ddemap/core/status.hpp"
#include "ddemap/solve/continuation.hpp"
#include <nlohmann/json.hpp>

namespace ddemap::detail {

using ojson = nlohmann::ordered_json;

/// The JSON text of `j`; a string that is not UTF-8 (a file path given on the command line: the
/// readers refuse names that are not) has each bad byte written as U+FFFD, never an exception.
template <class J>
std::string json_text(const J& j, int indent = -1) {
    return j.dump(indent, ' ', false, J::error_handler_t::replace);
}

inline ojson json_value(double v) { return std::isfinite(v) ? ojson(v) : ojson(nullptr); }

inline ojson json_values(const Eigen::VectorXd& x) {
    ojson a = ojson::array();
    for (Eigen::Index i = 0; i < x.size(); ++i) a.push_back(json_value(x[i]));
    return a;
}

/// A zero-Hopf point's normal form (analysis/bifurcation/normal_forms.hpp): {"g200", "g110", ...,
/// "theta"}, complex coefficients as {"re", "im"}; null when it was not formed.
inline ojson zero_hopf_normal_form_json(const ZeroHopfNormalForm& nf) {
    if (nf.status != Status::Converged) return ojson(nullptr);
    auto complex = [](cplx v) { return ojson{{"re", json_value(v.real())}, {"im", json_value(v.imag())}}; };
    ojson g;
    g["g200"] = json_value(nf.g200);
    g["g110"] = complex(nf.g110);
    g["g011"] = json_value(nf.g011);
    g["g300"] = json_value(nf.g300);
    g["g111"] = json_value(nf.g111);
    g["g210"] = complex(nf.g210);
    g["g021"] = complex(nf.g021);
    g["b"] = json_value(nf.b);
    g["c"] = json_value(nf.c);
    g["d"] = complex(nf.d);
    g["e"] = json_value(nf.e);
    g["s"] = json_value(nf.s);
    g["theta"] = json_value(nf.theta);
    return g;
}

/// A double Hopf point's normal form: {"g2100", "g1011", "g1110", "g0021" (as {"re", "im"}),
/// "theta", "delta"}; null when it was not formed.
inline ojson double_hopf_normal_form_json(const DoubleHopfNormalForm& nf) {
    if (nf.status != Status::Converged) return ojson(nullptr);
    auto complex = [](cplx v) { return ojson{{"re", json_value(v.real())}, {"im", json_value(v.imag())}}; };
    return ojson{{"g2100", complex(nf.g2100)}, {"g1011", complex(nf.g1011)}, {"g1110", complex(nf.g1110)},
                 {"g0021", complex(nf.g0021)}, {"theta", json_value(nf.theta)}, {"delta", json_value(nf.delta)}};
}

/// A generalised Hopf point's normal form: {"c1", "c2" (as {"re", "im"}), "l2"}; null when it was
/// not formed.
inline ojson generalised_hopf_normal_form_json(const GeneralisedHopfNormalForm& nf) {
    if (nf.status != Status::Converged) return ojson(nullptr);
    auto complex = [](cplx v) { return ojson{{"re", json_value(v.real())}, {"im", json_value(v.imag())}}; };
    return ojson{{"c1", complex(nf.c1)}, {"c2", complex(nf.c2)}, {"l2", json_value(nf.l2)}};
}

/// The head of a two-parameter curve's JSON (Hopf curves, fold curves): {"start", "status",
/// "message", "stop": [backward, forward]}; the caller adds its points.
inline ojson curve_json(int start, Status status, const std::string& message, ContinuationStop backward, ContinuationStop forward) {
    ojson o;
    o["start"] = start;
    o["status"] = to_string(status);
    o["message"] = message;
    o["stop"] = ojson::array({to_string(backward), to_string(forward)});
    return o;
}

}  // namespace ddemap::detail
