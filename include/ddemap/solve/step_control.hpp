#pragma once
/// \file step_control.hpp
/// The step control of ddemap's continuations, in one place: the equilibria and stability
/// boundaries (continue_branch, solve/continuation.hpp), the branches of periodic orbits and
/// travelling waves (analysis/periodic_orbit.hpp, analysis/travelling_wave.hpp) and the homotopy
/// in the wave number of long travelling waves all step with it. The rules, for a step h:
///   start      h_0 = initial_step;
///   jump       a corrected point at distance d > max_jump h from the last one left the branch
///              (the caller rejects the step);
///   rejection  h <- shrink_factor h; the continuation gives up when then h < min_step;
///   success    h <- min(max_step, grow_factor h) when the corrector was easy (the caller's
///              criterion, e.g. at most 3 Newton iterations), else h is kept.
/// The caller decides what a failure is (a corrector that did not converge, a jump, a turn of the
/// tangent, a point not resolved by the mesh) and what "easy" is; the controller only does the
/// arithmetic on h, so every caller's sequence of steps follows from the rules above.
/// (The argument-principle tracker follow_phase, core/phase_tracking.hpp, keeps its own rules:
/// it lives below this layer and its steps are capped by the phase's rate at every point.)

#include <algorithm>
#include <string>

namespace ddemap {

/// The numbers of the rules (each caller keeps its own through them).
struct StepControlOptions {
    double initial_step = 0.01;  ///< h_0
    double min_step = 1e-8;      ///< a rejection that leaves h < min_step ends the continuation
    double max_step = 0.1;       ///< the largest step growth reaches
    double shrink_factor = 0.5;  ///< h <- shrink_factor h after a rejection, in (0, 1)
    double grow_factor = 1.5;    ///< h <- min(max_step, grow_factor h) after an easy step, >= 1
    double max_jump = 3.0;       ///< a corrected point farther than max_jump h is a jump, > 0
    /// True when 0 < min_step <= initial_step <= max_step (finite) and the factors are in their
    /// ranges; otherwise `why` (if given) names the field.
    bool is_valid(std::string* why = nullptr) const;
};

/// The step h of a continuation under the rules of StepControlOptions (see the file comment).
class StepControl {
public:
    /// Throws std::invalid_argument when the options are not valid.
    explicit StepControl(const StepControlOptions& options);
    /// the current step h
    double h() const { return m_h; }
    /// max_jump h: the farthest a corrected point may lie from the last one
    double jump_limit() const { return m_options.max_jump * m_h; }
    /// d > max_jump h: the corrector left the branch
    bool jumped(double distance) const { return distance > jump_limit(); }
    /// After a rejected step: h <- shrink_factor h; false when h < min_step (give up).
    [[nodiscard]] bool reject() {
        m_h *= m_options.shrink_factor;
        return m_h >= m_options.min_step;
    }
    /// After an accepted step: h <- min(max_step, grow_factor h) when `easy`, else unchanged.
    void accept(bool easy) {
        if (easy) m_h = std::min(m_options.max_step, m_options.grow_factor * m_h);
    }

private:
    StepControlOptions m_options;
    double m_h;
};

}  // namespace ddemap
