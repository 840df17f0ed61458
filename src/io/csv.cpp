#include "ddemap/io/csv.hpp"

#include <cstdio>
#include <sstream>

namespace ddemap {

std::string format_exact(double v) {
    char b[40];
    std::snprintf(b, sizeof b, "%.17g", v == 0.0 ? 0.0 : v);
    return b;
}

std::string sweep_csv(const SweepResult& sw) {
    std::ostringstream s;
    s << sw.spec.x.name << "," << sw.spec.y.name
      << ",spectral_abscissa,unstable_roots,sup_gamma,omega_peak,plant_stable,ring_stable,string_stable,"
         "abscissa_mode,plant_abscissa,lowfreq_margin,peak_gain,certified\n";
    auto b = [](bool v) { return v ? "true" : "false"; };
    for (const auto& p : sw.points) {
        s << format_exact(p.x) << "," << format_exact(p.y) << "," << format_exact(p.spectral_abscissa) << ",";
        if (p.unstable_roots >= 0) s << p.unstable_roots;
        s << "," << format_exact(p.sup_gamma) << "," << format_exact(p.omega_peak) << "," << b(p.plant_stable) << ","
          << b(p.ring_stable) << "," << b(p.string_stable) << ",";
        if (p.abscissa_mode >= 0) s << p.abscissa_mode;
        s << "," << format_exact(p.plant_abscissa) << "," << format_exact(p.lowfreq_margin) << "," << format_exact(p.peak_gain)
          << "," << b(p.certified) << "\n";
    }
    return s.str();
}

std::string boundary_csv(const SweepSpec& spec, const BoundarySet& set) {
    std::ostringstream s;
    s << "branch,kind,subkind,mode," << spec.x.name << "," << spec.y.name << ",omega\n";
    for (std::size_t i = 0; i < set.curves.size(); ++i) {
        const auto& c = set.curves[i];
        for (const auto& p : c.points) {
            s << i + 1 << "," << kind_name(c.kind) << "," << subkind_name(c.kind) << ",";
            if (c.kind == BoundaryKind::RingHopf) s << c.mode;
            s << "," << format_exact(p.x) << "," << format_exact(p.y) << "," << format_exact(p.omega) << "\n";
        }
    }
    return s.str();
}

}  // namespace ddemap
