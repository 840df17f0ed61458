#pragma once
/// \file attenuation_margin.hpp
/// The attenuation margin of a string-stable car: the largest time constant m (seconds) such that
/// every wave is damped from car to car at least as a first-order lag of m seconds damps it,
///     |Gamma(i w)| <= 1 / |1 + i m w|   for every w > 0.
/// Squaring, 1/|Gamma|^2 - 1 >= m^2 w^2, that is m^2 <= mu with
///     mu = inf_{w > 0} (|D(i w)|^2 - |N(i w)|^2) / (w^2 |N(i w)|^2) = inf_{w > 0} q(w) / |N(i w)|^2
/// (q of TransferFunction::attenuation, formed without cancellation). mu has units s^2; it tends
/// to c2 / D(0)^2 as w -> 0 (LowFrequency::c2) and to 1/|lead(i w)|^2 as w -> infinity. The car
/// is string stable (L2, with a stable plant) exactly when mu >= 0, strictly inside the region
/// when mu > 0; the signed margin m* = sign(mu) sqrt(|mu|) is continuous across the boundary of
/// string stability, where sup |Gamma(i w)| - 1 vanishes only quadratically: it measures how far
/// a car is from string stability and how much it attenuates (an ideal cooperative cruise
/// control with Gamma = 1/(1 + h s) has m* = h).

#include <vector>

#include "ddemap/traffic/transfer_function.hpp"

namespace ddemap {

/// What one scan of the imaginary axis gives: sup |Gamma(i w)| and mu, each with the frequency
/// where it is reached. A scan, not a certificate: a log grid of `grid` points over 10 decades
/// about the car's natural frequency, the best three local extrema of each refined by golden
/// sections in log w to 1e-10 relative; the certified verdicts are analyse_string's.
struct AttenuationScan {
    double sup_gamma = 1.0;    ///< max(1, the largest |Gamma(i w)| found)
    double omega_sup = 0.0;    ///< rad/s where it is reached (0: only the limit w -> 0, value 1)
    double mu = 0.0;           ///< s^2: the smallest q / |N|^2 found, the limit w -> 0 included
    double omega_mu = 0.0;     ///< rad/s where it is reached (0: the limit w -> 0, c2 / D(0)^2)
    double margin = 0.0;       ///< s: sign(mu) sqrt(|mu|), the signed attenuation margin
    double weight = 0.0;       ///< s: the m of the weighted norm below (the scan's argument)
    /// sup_w |Gamma(i w)| |1 + i m w| (>= 1; 1 exactly when margin >= m, to the scan)
    double weighted_sup = 1.0;
    double omega_weighted = 0.0;  ///< rad/s where it is reached (0: only the limit w -> 0)
    int evaluations = 0;       ///< evaluations of N and D
    /// The pieces of mu: the limit w -> 0 (omega 0, c2 / D(0)^2), every refined local minimum of
    /// q/|N|^2 over the scan (at most three), and the scan's last frequency when q/|N|^2 still
    /// falls there (the approach to 1/|lead(i w)|^2). mu is the least of them; each is smooth in
    /// the law's parameters at its fixed frequency (the constraints of a nearest-gains search).
    struct Minimum {
        double omega = 0.0;
        double mu = 0.0;
    };
    std::vector<Minimum> mu_minima;
};

/// The scan for the transfer function of `lin` (single leader; D(0) != 0, else
/// std::invalid_argument). Meaningful for a stable plant only (the caller checks it).
/// `weight` m >= 0 (s) of the weighted norm sup |Gamma(i w)| |1 + i m w|.
AttenuationScan attenuation_scan(const Linearisation& lin, double weight = 0.0, int grid = 800);

/// One piece of the margin condition mu >= m2 at a fixed frequency w >= 0, smooth in the law's
/// parameters:
///     g = (q(w) - m2 |N(i w)|^2) / |N(i w)|         (w > 0),
///     g = (c2 - m2 D(0)^2) / |D(0)|                  (w = 0, the limit),
/// so that mu >= m2 exactly when g >= 0 at every w (q as in mu above). With m2 = 0 its sign is
/// that of 1 - |Gamma(i w)|^2 (w > 0) or of c2 (w = 0). NaN where N(i w) = 0.
double attenuation_piece(const Linearisation& lin, double omega, double m2);

}  // namespace ddemap
