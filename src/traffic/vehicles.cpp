#include "ddemap/traffic/vehicles.hpp"

#include "core/internal/text.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

namespace ddemap {

const std::vector<CalibratedVehicle>& paper_calibration_table() {
    struct Row {
        const char* vehicle;
        const char* setting;
        double k1, k2, th, tau, eta;
    };
    // transcribed from the paper's calibration table
    static const Row rows[] = {
        {"A", "min", 0.052, 0.338, 0.819, 0.948, 8.030}, {"A", "max", 0.012, 0.167, 2.054, 0.992, 5.960},
        {"B", "min", 0.052, 0.190, 0.725, 0.468, 6.849}, {"B", "max", 0.022, 0.116, 2.020, 0.153, 8.210},
        {"C", "min", 0.029, 0.269, 0.907, 0.368, 10.070}, {"C", "max", 0.018, 0.152, 1.986, 0.324, 13.814},
        {"D", "min", 0.051, 0.280, 0.544, 0.284, 13.400}, {"D", "max", 0.022, 0.221, 1.853, 0.935, 14.956},
        {"E", "min", 0.051, 0.165, 1.127, 0.419, 5.170}, {"E", "max", 0.053, 0.142, 1.785, 0.839, 9.370},
        {"F", "min", 0.071, 0.191, 0.696, 0.582, 10.090}, {"F", "max", 0.041, 0.164, 1.734, 0.922, 6.033},
        {"G", "min", 0.070, 0.253, 0.549, 0.993, 14.500}, {"G", "max", 0.046, 0.129, 1.764, 0.994, 5.131},
    };
    static const std::vector<CalibratedVehicle> table = [] {
        std::vector<CalibratedVehicle> t;
        for (const auto& r : rows) {
            CalibratedVehicle v;
            v.vehicle = r.vehicle;
            v.setting = r.setting;
            v.name = v.vehicle + "_" + v.setting;
            v.make = (v.vehicle < "E") ? 1 : 2;
            v.min_acc_speed = v.make == 1 ? 11.176 : 0.0;  // 25 mph
            v.parameters = {{"k1", r.k1}, {"k2", r.k2}, {"th", r.th}, {"tau", r.tau}, {"eta", r.eta}};
            t.push_back(v);
        }
        return t;
    }();
    return table;
}

const CalibratedVehicle& builtin_vehicle(const std::string& name) {
    for (const auto& v : paper_calibration_table())
        if (v.name == name) return v;
    throw std::invalid_argument("vehicle " + detail::quoted(name) + ": expected a name of the calibration table (A_min .. G_max)");
}

std::vector<std::string> covariance_column_names() {
    static const char* names[] = {"k1", "k2", "th", "tau", "eta"};
    std::vector<std::string> out;
    for (int a = 0; a < 5; ++a)
        for (int b = a; b < 5; ++b) out.push_back(std::string("cov_") + names[a] + "_" + names[b]);
    return out;
}

std::vector<std::string> bounds_column_names() {
    std::vector<std::string> out;
    for (const char* n : {"k1", "k2", "th", "tau", "eta"}) {
        out.push_back(std::string("lo_") + n);
        out.push_back(std::string("hi_") + n);
    }
    return out;
}

std::vector<CalibratedVehicle> read_vehicles_csv(const std::string& text, const std::string& source) {
    detail::CsvReader csv(text, source, "name,k1,k2,th,tau[,eta]");
    const int c_name = csv.column("name");
    const char* params[] = {"k1", "k2", "th", "tau", "eta"};
    int c_param[5];
    for (int i = 0; i < 5; ++i) c_param[i] = csv.column(params[i], i < 4);
    const int c_min_speed = csv.column("min_acc_speed", false);
    const std::vector<std::string> cov_names = covariance_column_names();
    std::vector<int> c_cov;
    for (const auto& n : cov_names) c_cov.push_back(csv.column(n, false));
    const auto cov_given = static_cast<int>(std::count_if(c_cov.begin(), c_cov.end(), [](int c) { return c >= 0; }));
    if (cov_given > 0 && cov_given < 15)
        throw std::invalid_argument(source + ": the header has " + std::to_string(cov_given) +
                                    " of the 15 covariance columns cov_k1_k1 .. cov_eta_eta: expected all or none");
    // the calibration's bounds: for each parameter lo_NAME and hi_NAME, both or neither
    const std::vector<std::string> bound_names = bounds_column_names();
    std::vector<int> c_bound;
    for (const auto& n : bound_names) c_bound.push_back(csv.column(n, false));
    for (std::size_t i = 0; i < 5; ++i)
        if ((c_bound[2 * i] >= 0) != (c_bound[2 * i + 1] >= 0))
            throw std::invalid_argument(source + ": the header has " + (c_bound[2 * i] >= 0 ? bound_names[2 * i] : bound_names[2 * i + 1]) +
                                        " without " + (c_bound[2 * i] >= 0 ? bound_names[2 * i + 1] : bound_names[2 * i]) +
                                        ": expected both bounds of " + params[i] + " or neither");
    std::vector<CalibratedVehicle> out;
    while (csv.next()) {
        CalibratedVehicle v;
        v.name = csv.fields()[c_name];
        if (v.name.empty()) csv.fail("column 'name' is empty: expected a vehicle name");
        v.vehicle = v.name;
        v.parameters["eta"] = 10.0;
        for (int i = 0; i < 5; ++i)
            if (c_param[i] >= 0) v.parameters[params[i]] = csv.number(c_param[i], params[i]);
        if (c_min_speed >= 0 && !csv.fields()[c_min_speed].empty()) {
            v.min_acc_speed = csv.number(c_min_speed, "min_acc_speed");
            if (v.min_acc_speed < 0.0) csv.fail("min_acc_speed = " + csv.fields()[c_min_speed] + ": expected >= 0 m/s");
        }
        if (cov_given == 15) {
            int filled = 0;
            for (int c : c_cov) filled += csv.fields()[static_cast<std::size_t>(c)].empty() ? 0 : 1;
            if (filled != 0 && filled != 15)
                csv.fail(std::to_string(filled) + " of the 15 covariance columns are filled: expected all or none");
            if (filled == 15) {
                std::size_t k = 0;
                for (int a = 0; a < 5; ++a)
                    for (int b = a; b < 5; ++b, ++k) {
                        const double x = csv.number(c_cov[k], cov_names[k]);
                        if (a == b && x < 0.0) csv.fail("column '" + cov_names[k] + "' = " + csv.fields()[static_cast<std::size_t>(c_cov[k])] + ": expected a variance >= 0");
                        v.covariance(a, b) = v.covariance(b, a) = x;
                    }
                v.has_covariance = true;
            }
        }
        for (std::size_t i = 0; i < 5; ++i) {
            const int cl = c_bound[2 * i], ch = c_bound[2 * i + 1];
            if (cl < 0) continue;
            const bool fl = !csv.fields()[static_cast<std::size_t>(cl)].empty(), fh = !csv.fields()[static_cast<std::size_t>(ch)].empty();
            if (fl != fh) csv.fail(bound_names[2 * i] + " and " + bound_names[2 * i + 1] + ": expected both filled or both empty");
            if (!fl) continue;
            const double lo = csv.number(cl, bound_names[2 * i]), hi = csv.number(ch, bound_names[2 * i + 1]);
            if (lo < 0.0) csv.fail(bound_names[2 * i] + " = " + csv.fields()[static_cast<std::size_t>(cl)] + ": expected >= 0 (the model's domain)");
            if (!(lo <= hi))
                csv.fail(bound_names[2 * i] + " = " + detail::format_number(lo) + " above " + bound_names[2 * i + 1] + " = " +
                         detail::format_number(hi) + ": expected lower <= upper");
            v.bounds.push_back({params[i], lo, hi});
        }
        try {
            (void)make_model("ovrv", v.parameters);
        } catch (const std::invalid_argument& e) {
            csv.fail(e.what());
        }
        out.push_back(v);
    }
    if (out.empty()) throw std::invalid_argument(source + ": no vehicles after the header");
    return out;
}

}  // namespace ddemap
