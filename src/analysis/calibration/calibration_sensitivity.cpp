// The follower simulation of the calibration with its forward sensitivities (calibrate.hpp).
// A dedicated RK4 (not DdeSolver): the state is augmented with S = d(s, v)/d theta,
// the steps land on the samples t_k (kinks of the interpolated lead) and on their delayed echoes
// t_k + tau, and the data history needs its slopes for the tau-sensitivity.
#include <algorithm>
#include <cmath>

#include "ddemap/analysis/calibration/calibrate.hpp"

namespace ddemap {

namespace {

constexpr int P = 5;          // parameters
constexpr int SS = 2;         // offset of S_s (5 entries), S_v at SS + P
constexpr int NSENS = 2 + 2 * P;

/// Piecewise-linear data y(t) on one segment [t_k, t_{k+1}], constant outside the samples.
struct Segment {
    double t = 0.0, y = 0.0, slope = 0.0;
    double value(double x) const { return y + slope * (x - t); }
};

/// the segment of the samples containing x (for x at a sample, the one to its right; `left`:
/// the one to its left); outside the samples a constant
Segment segment(const std::vector<double>& t, const std::vector<double>& y, double x, bool left) {
    const std::size_t n = t.size();
    if (x < t.front() || (left && x <= t.front())) return {x, y.front(), 0.0};
    if (x > t.back() || (!left && x >= t.back())) return {x, y.back(), 0.0};
    std::size_t k = left ? static_cast<std::size_t>(std::lower_bound(t.begin(), t.end(), x) - t.begin()) - 1
                         : static_cast<std::size_t>(std::upper_bound(t.begin(), t.end(), x) - t.begin()) - 1;
    k = std::min(k, n - 2);
    return {t[k], y[k], (y[k + 1] - y[k]) / (t[k + 1] - t[k])};
}

class Integrator {
public:
    Integrator(const Trace& tr, const CalibrationVector& th, bool sens) : m_tr(tr), m_p(th), m_n(sens ? NSENS : 2), m_sens(sens) {}

    FollowerTrajectory run(double t_a, double t_b, double h_max, double t_start) {
        const double tau = m_p[3];
        m_ta = t_a;
        // the start moves with tau only when the history window [t_a, t_a + tau] reaches past t_start
        const bool moving = t_a + tau >= t_start;
        m_t0 = moving ? t_a + tau : t_start;
        // breakpoints: samples and their delayed echoes in (t0, t_b], t0 + tau, t_b
        std::vector<double> bp;
        for (double t : m_tr.t) {
            if (t > m_t0 && t <= t_b) bp.push_back(t);
            if (t + tau > m_t0 && t + tau <= t_b) bp.push_back(t + tau);
        }
        if (m_t0 + tau < t_b && tau > 0.0) bp.push_back(m_t0 + tau);
        if (t_b > m_t0) bp.push_back(t_b);
        std::sort(bp.begin(), bp.end());
        m_T.clear();
        m_Y.clear();
        m_F.clear();
        // initial state at t0: the data; S_tau(t0) = x_data'(t0) - x'(t0)
        std::vector<double> y(m_n, 0.0), f(m_n), k2(m_n), k3(m_n), k4(m_n), tmp(m_n);
        const Segment g0 = segment(m_tr.t, m_tr.gap, m_t0, false), v0 = segment(m_tr.t, m_tr.speed, m_t0, false);
        y[0] = g0.value(m_t0);
        y[1] = v0.value(m_t0);
        double prev = m_t0;
        StepData sd = step_data(m_t0, std::min(h_max, bp.empty() ? h_max : bp.front() - m_t0));
        rhs(m_t0, y.data(), sd, f.data());
        if (m_sens && moving) {
            y[SS + 3] = g0.slope - f[0];
            y[SS + P + 3] = v0.slope - f[1];
            rhs(m_t0, y.data(), sd, f.data());
        }
        push(m_t0, y.data(), f.data());
        for (double target : bp) {
            if (target - prev < 1e-9) continue;
            const int m = static_cast<int>(std::ceil((target - prev) / h_max - 1e-9));
            const double h = (target - prev) / m;
            for (int j = 0; j < m; ++j) {
                const double t = prev + j * h;
                const double te = j + 1 == m ? target : t + h;
                const double hh = te - t;
                sd = step_data(t, hh);
                const double* yc = &m_Y[m_Y.size() - m_n];
                const double* fc = &m_F[m_F.size() - m_n];
                for (int i = 0; i < m_n; ++i) tmp[i] = yc[i] + 0.5 * hh * fc[i];
                rhs(t + 0.5 * hh, tmp.data(), sd, k2.data());
                for (int i = 0; i < m_n; ++i) tmp[i] = yc[i] + 0.5 * hh * k2[i];
                rhs(t + 0.5 * hh, tmp.data(), sd, k3.data());
                for (int i = 0; i < m_n; ++i) tmp[i] = yc[i] + hh * k3[i];
                rhs(te, tmp.data(), sd, k4.data());
                for (int i = 0; i < m_n; ++i) y[i] = yc[i] + hh / 6.0 * (fc[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
                // the derivative at the step's end, with the delayed inputs of this step (left limits)
                rhs(te, y.data(), sd, f.data());
                // a car that has come to rest stays at v = 0 whatever theta: S_v jumps to 0 there
                // (S_v(t_e-) = -v'(t_e-) dt_e/dtheta; s is C^1, so S_s is continuous)
                // (the overshoot of the step below 0 is cut: the car rests at v = 0 exactly)
                if (m_stopped) {
                    y[1] = 0.0;
                    if (m_sens)
                        for (int i = 0; i < P; ++i) y[SS + P + i] = 0.0;
                    rhs(te, y.data(), sd, f.data());
                }
                push(te, y.data(), f.data());
            }
            prev = target;
        }
        // output at the samples of [t_a, t_b]
        FollowerTrajectory out;
        std::vector<std::size_t> rows;
        for (std::size_t k = 0; k < m_tr.t.size(); ++k)
            if (m_tr.t[k] >= t_a && m_tr.t[k] <= t_b) rows.push_back(k);
        const std::size_t n = rows.size();
        out.time.resize(n);
        out.speed.resize(n);
        out.gap.resize(n);
        if (m_sens) {
            out.dspeed = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(n), P);
            out.dgap = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(n), P);
        }
        std::size_t cursor = 0;
        std::vector<double> val(m_n), der(m_n);
        for (std::size_t r = 0; r < n; ++r) {
            const std::size_t k = rows[r];
            const double t = m_tr.t[k];
            out.time[r] = t;
            if (t <= m_t0 || m_T.size() < 2) {
                out.speed[r] = m_tr.speed[k];
                out.gap[r] = m_tr.gap[k];
                continue;
            }
            while (cursor + 2 < m_T.size() && m_T[cursor + 1] < t) ++cursor;
            hermite(cursor, t, 0, m_n, val.data(), der.data());
            out.gap[r] = val[0];
            out.speed[r] = val[1];
            if (m_sens)
                for (int i = 0; i < P; ++i) {
                    out.dgap(static_cast<Eigen::Index>(r), i) = val[SS + i];
                    out.dspeed(static_cast<Eigen::Index>(r), i) = val[SS + P + i];
                }
        }
        return out;
    }

private:
    /// inputs constant in form over one step: the lead at t and at t - tau, the data history
    struct StepData {
        Segment lead, lead_delayed, gap_hist;
    };
    StepData step_data(double t, double h) const {
        const double mid = t + 0.5 * h, tau = m_p[3];
        StepData d;
        d.lead = segment(m_tr.t, m_tr.lead, mid, false);
        d.lead_delayed = segment(m_tr.t, m_tr.lead, mid - tau, false);
        d.gap_hist = segment(m_tr.t, m_tr.gap, mid - tau, false);
        return d;
    }

    void push(double t, const double* y, const double* f) {
        m_T.push_back(t);
        m_Y.insert(m_Y.end(), y, y + m_n);
        m_F.insert(m_F.end(), f, f + m_n);
    }

    /// cubic Hermite on stored interval [T_j, T_{j+1}] (extrapolated outside it): components
    /// [c0, c1) into val, their time derivatives into der
    void hermite(std::size_t j, double t, int c0, int c1, double* val, double* der) const {
        const double h = m_T[j + 1] - m_T[j], s = (t - m_T[j]) / h;
        const double h00 = (1 + 2 * s) * (1 - s) * (1 - s), h10 = s * (1 - s) * (1 - s), h01 = s * s * (3 - 2 * s), h11 = s * s * (s - 1);
        const double d00 = 6 * s * (s - 1) / h, d10 = (1 - s) * (1 - 3 * s), d01 = -d00, d11 = s * (3 * s - 2);
        const double* y0 = &m_Y[j * m_n];
        const double* y1 = y0 + m_n;
        const double* f0 = &m_F[j * m_n];
        const double* f1 = f0 + m_n;
        for (int i = c0; i < c1; ++i) {
            val[i] = h00 * y0[i] + h10 * h * f0[i] + h01 * y1[i] + h11 * h * f1[i];
            der[i] = d00 * y0[i] + d10 * f0[i] + d01 * y1[i] + d11 * f1[i];
        }
    }

    /// the delayed gap s(u) at u = t - tau, its time derivative, and (sensitivities) S_s(u)
    void delayed(double u, const StepData& sd, double& s, double& ds, double* S) {
        if (u <= m_t0) {  // the data history: independent of theta at fixed u
            s = sd.gap_hist.value(u);
            ds = sd.gap_hist.slope;
            if (S)
                for (int i = 0; i < P; ++i) S[i] = 0.0;
            return;
        }
        if (m_T.size() < 2) {  // no completed step yet (tau below the step): linear from t0
            const double dt = u - m_T[0];
            s = m_Y[0] + dt * m_F[0];
            ds = m_F[0];
            if (S)
                for (int i = 0; i < P; ++i) S[i] = m_Y[SS + i] + dt * m_F[SS + i];
            return;
        }
        if (u < m_T[m_cur]) m_cur = 0;
        while (m_cur + 2 < m_T.size() && m_T[m_cur + 1] < u) ++m_cur;
        double val[NSENS], der[NSENS];
        hermite(m_cur, u, 0, 1, val, der);
        s = val[0];
        ds = der[0];
        if (S) {
            hermite(m_cur, u, SS, SS + P, val, der);
            for (int i = 0; i < P; ++i) S[i] = val[SS + i];
        }
    }

    void rhs(double t, const double* y, const StepData& sd, double* dy) {
        const double k1 = m_p[0], k2 = m_p[1], th = m_p[2], tau = m_p[3], eta = m_p[4];
        const double vl = sd.lead.value(t);
        double s_d, ds_d, S_d[P];
        if (tau > 0.0) {
            delayed(t - tau, sd, s_d, ds_d, m_sens ? S_d : nullptr);
        } else {
            s_d = y[0];
            ds_d = vl - y[1];
            if (m_sens)
                for (int i = 0; i < P; ++i) S_d[i] = y[SS + i];
        }
        const double vld = tau > 0.0 ? sd.lead_delayed.value(t - tau) : vl;
        const double dvld = sd.lead_delayed.slope;
        dy[0] = vl - y[1];
        double a = k1 * (s_d - eta - th * y[1]) + k2 * (vld - y[1]);
        const bool stopped = y[1] <= 0.0 && a < 0.0;  // standing cars do not roll backwards
        m_stopped = stopped;
        if (stopped) a = 0.0;
        dy[1] = a;
        if (!m_sens) return;
        const double* Sv = y + SS + P;
        for (int i = 0; i < P; ++i) dy[SS + i] = -Sv[i];
        if (stopped) {
            for (int i = 0; i < P; ++i) dy[SS + P + i] = 0.0;
            return;
        }
        // d a / d theta_i = k1 (dsd_i - th Sv_i) - k2 Sv_i + explicit_i
        const double explicit_[P] = {s_d - eta - th * y[1], vld - y[1], -k1 * y[1],
                                     -k1 * ds_d - k2 * dvld,  // tau: -s'(t - tau), -v_l'(t - tau)
                                     -k1};
        for (int i = 0; i < P; ++i) dy[SS + P + i] = k1 * (S_d[i] - th * Sv[i]) - k2 * Sv[i] + explicit_[i];
    }

    const Trace& m_tr;
    CalibrationVector m_p;
    int m_n;
    bool m_sens;
    double m_ta = 0.0, m_t0 = 0.0;
    std::vector<double> m_T, m_Y, m_F;
    std::size_t m_cur = 0;
    bool m_stopped = false;  // at the last rhs evaluation
};

}  // namespace

FollowerTrajectory simulate_follower(const Trace& trace, const CalibrationVector& theta, double t_a, double t_b, double step,
                                     bool sensitivities, double t_start) {
    Integrator in(trace, theta, sensitivities);
    return in.run(t_a, t_b, step, t_start);
}

}  // namespace ddemap
