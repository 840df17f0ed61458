#include "ddemap/solve/step_control.hpp"

#include <cmath>
#include <stdexcept>

namespace ddemap {

bool StepControlOptions::is_valid(std::string* why) const {
    const char* w = nullptr;
    if (!(min_step > 0.0 && min_step <= initial_step && initial_step <= max_step && std::isfinite(max_step)))
        w = "steps: expected 0 < min_step <= initial_step <= max_step (finite)";
    else if (!(shrink_factor > 0.0 && shrink_factor < 1.0)) w = "shrink_factor: expected a value in (0, 1)";
    else if (!(std::isfinite(grow_factor) && grow_factor >= 1.0)) w = "grow_factor: expected a finite value >= 1";
    else if (!(std::isfinite(max_jump) && max_jump > 0.0)) w = "max_jump: expected a finite value > 0";
    if (w && why) *why = w;
    return w == nullptr;
}

StepControl::StepControl(const StepControlOptions& options) : m_options(options), m_h(options.initial_step) {
    std::string why;
    if (!options.is_valid(&why)) throw std::invalid_argument("step control: " + why);
}

}  // namespace ddemap
