#pragma once
// JSON values shared by the io writers (private): a double as a number, or null when it is not
// finite (JSON has no NaN or infinity), and a vector as an array of those.
#include <cmath>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

namespace ddemap::detail {

using ojson = nlohmann::ordered_json;

inline ojson json_value(double v) { return std::isfinite(v) ? ojson(v) : ojson(nullptr); }

inline ojson json_values(const Eigen::VectorXd& x) {
    ojson a = ojson::array();
    for (Eigen::Index i = 0; i < x.size(); ++i) a.push_back(json_value(x[i]));
    return a;
}

}  // namespace ddemap::detail
