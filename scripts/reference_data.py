#!/usr/bin/env python3
r"""Independent high-precision reference data for the OVRV ring / string analysis.

This script is deliberately self-contained: it uses only the Python standard
library and mpmath (40 significant digits) and does not look at, import or
call any of the project's C++ code.  Its output is the provenance of

    tests/data/reference_ring_roots.csv
    tests/data/reference_string.csv

Model
-----
OVRV car following with sensing delay ``tau`` (``tau >= 0``), parameters
``k1`` [1/s^2], ``k2`` [1/s], ``th`` [s].  Partial derivatives

    f_s = k1,   f_v = -(k1*th + k2),   f_l = k2.

Ring of N identical cars, Fourier mode m, ``zeta_m = exp(-2*pi*i*m/N)``:

    f_m(lam) = lam^2 - f_v*lam + f_s*e^{-lam*tau} - zeta_m*e^{-lam*tau}*(f_s + f_l*lam)

Mode 0 factors as ``lam * g(lam)`` with ``g(lam) = lam - f_v - f_l*e^{-lam*tau}``;
the trivial root ``lam = 0`` is removed by working with ``g`` instead.  Roots
of mode N-m are the conjugates of those of mode m, so only m = 0..floor(N/2)
are tabulated.

Head-to-tail transfer function and plant denominator:

    Gamma(s) = (f_s + f_l*s)*e^{-s*tau} / D(s),   D(s) = s^2 - f_v*s + f_s*e^{-s*tau}.

Every function handled here has the common form

    F(lam) = a2*lam^2 + a1*lam + a0 + (b1*lam + b0)*e^{-lam*tau}

(mode m != 0: a2=1, a1=-f_v, a0=0, b1=-zeta*f_l, b0=f_s*(1-zeta);
 mode 0 (g):   a2=0, a1=1,    a0=-f_v, b1=0,    b0=-f_l;
 plant D:      a2=1, a1=-f_v, a0=0,    b1=0,    b0=f_s).

Finding ALL roots in a right region
-----------------------------------
1. A-priori bound.  If F(lam)=0 and Re(lam) >= sigma then, because tau >= 0,
   |e^{-lam*tau}| = e^{-Re(lam)*tau} <= E := e^{-sigma*tau}, hence

       a2=1:  |lam|^2 <= (|a1| + E|b1|)|lam| + (|a0| + E|b0|)
              =>  |lam| <= R := (b + sqrt(b^2 + 4c))/2,
                  b = |a1| + E|b1|,  c = |a0| + E|b0|;
       a2=0, a1=1, b1=0:  |lam| <= R := |a0| + E|b0|.

   For mode m this is the bound x^2 - b x - c = 0 with
   b = |f_v| + |f_l|E and c = |f_s||1-zeta|E <= 2|f_s|E (we use the slightly
   sharper but equally rigorous |1 - zeta| instead of 1 + |zeta| = 2).
   Every root with Re >= sigma therefore lies in the rectangle
   [sigma, R+1] x [-(R+1), R+1], at distance >= 1 from its right, top and
   bottom sides.
2. Counting.  The number of roots inside the rectangle is the winding number
   of F along its boundary (argument principle).  The boundary is walked with
   adaptive steps at 40 digits; a step is accepted only if each of its two
   halves changes arg F by less than pi/8 and |F| by less than a factor 2
   (this rules out aliasing and detects roots close to the contour; if a root
   is within ~1e-9 of the left side, sigma is shifted slightly).  The total
   phase change divided by 2*pi must be an integer to 1e-6.  As a second,
   independent evaluation the final count of every problem is also obtained
   by integrating F'/F along the contour with mpmath.quad (20 digits); both
   must agree.
3. Finding.  Newton's method (double precision, analytic derivative) is
   started from a grid of points covering the rectangle; the converged points
   inside the rectangle are polished with mpmath.findroot (Newton, analytic
   derivative) to 40 digits, and deduplicated (relative distance < 1e-20).
   The number of distinct roots must equal the argument-principle count; if
   it does not, the start grid is refined (up to 4 times) and the search
   repeated.  Any remaining disagreement aborts the script.
4. sigma starts at -3.  If fewer roots than required (3 for a ring mode, 1
   for the plant) have Re > sigma, sigma is lowered over the integers
   -4, -5, ..., -15 and the first sigma with enough roots is used (the
   counts are checked to be monotone in sigma).
   If even Re > -15 contains fewer roots, just those are reported: a ring
   mode with fewer than three rows in the CSV has NO further root with
   Re(lam) > -15 (for small tau the delay-induced root chains lie far to the
   left).
5. For tau = 0 the functions are polynomials; their roots are taken from
   mpmath.polyroots and cross-checked against steps 1-3.

String stability (reference_string.csv)
---------------------------------------
* plant_abscissa: the largest real part of the roots of D (all roots with
  Re > sigma found as above).
* |Gamma(i w)|^2 = P(w)/Q(w) with P = f_s^2 + f_l^2 w^2 and
  Q = |D(iw)|^2 = w^4 + (f_v^2 - 2 f_s cos(w tau)) w^2 + 2 f_v f_s w sin(w tau) + f_s^2
  (both checked numerically against the complex expressions).
  sup_{w>0} |Gamma(iw)| is located by sampling a 20000-point log grid from
  1e-4 (extended downwards if needed) to W, where W is chosen from the bound
  |Gamma(iw)| <= (|f_s| + |f_l| w)/(w^2 - |f_v| w - |f_s|) so that |Gamma| < 1/2
  for all w >= W, plus the positive imaginary parts of the plant roots.  Every
  sampled local maximum is refined by bisection on the sign of
  d/dw (P/Q) (analytic derivative) to ~1e-35 relative, and the largest is
  reported as (sup_gamma, omega_peak).  If c2 > 0 and no local maximum
  exceeds 1, the supremum is the limit |Gamma(0)| = 1 approached as w -> 0,
  and (1, 0) is reported.
* c2 = f_v^2 + 2 f_v f_s tau - 2 f_s - f_l^2, the coefficient of w^2 in
  |D(iw)|^2 - |N(iw)|^2 (N = (f_s + f_l s) e^{-s tau}).  It is verified
  numerically against the quotient (|D|^2 - |N|^2)/w^2 at w = 1e-10, computed
  from the complex expressions of D and N.

Inputs and output format
------------------------
The parameters are written to the CSV in shortest round-trip form (e.g.
``0.2``) and the computation uses the exact binary64 value of that decimal,
so the reference applies exactly to the doubles a consumer parses.  Computed
values are correctly rounded (round-to-nearest) to binary64 and printed with
``%.17g`` (17 significant digits, round-trip exact).  Imaginary parts of
roots of real-coefficient functions that are real to within 1e-30 are
printed as exactly 0.

Ring roots: for each case and N in {2, 3, 5, 10, 22, 50}, for m = 0..floor(N/2),
the up-to-3 rightmost roots of mode m, rank 0 = largest real part; real parts
equal to within 1e-30 (conjugate pairs of real-coefficient modes) are ordered
by larger imaginary part first.

Self-checks (asserts) at the end: residual |F| < 1e-30 for every root; c2
formula; the 14 calibration settings should have c2 < 0 and sup_gamma > 1
(reported if not); the Lambert-W test lam = a e^{-lam tau} (a=-1, tau=1)
whose rightmost roots must equal W_0(a tau)/tau and W_{-1}(a tau)/tau to 1e-30
and whose root count must match the number of Lambert-W branches.

Usage:  scripts/reference_data.py     (run from anywhere; about 10 minutes on 2 cores)
"""

import cmath
import functools
import math
import os
import random
import sys
import time
from fractions import Fraction
from multiprocessing import Pool

import mpmath
from mpmath import mp, mpc, mpf

mp.dps = 40

ROOT_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT_RING = os.path.join(ROOT_DIR, "tests", "data", "reference_ring_roots.csv")
OUT_STRING = os.path.join(ROOT_DIR, "tests", "data", "reference_string.csv")

RING_SIZES = (2, 3, 5, 10, 22, 50)
ROOTS_PER_MODE = 3
SIGMA_LIST = [-3 - j for j in range(13)]   # -3, -4, ..., -15
R_CAP = 2000.0                              # refuse absurdly large rectangles
RESIDUAL_TOL = mpf("1e-30")
DEDUP_REL = mpf("1e-20")
TIE_TOL = mpf("1e-30")
PROCESSES = 2


# ---------------------------------------------------------------------------
# Cases
# ---------------------------------------------------------------------------

def build_cases():
    """Return the fixed list of (name, k1, k2, th, tau) with float inputs."""
    cases = [("paper_example", 0.2, 0.2, 1.5, 0.1)]
    calibration = """
        A_min 0.052 0.338 0.819 0.948
        A_max 0.012 0.167 2.054 0.992
        B_min 0.052 0.190 0.725 0.468
        B_max 0.022 0.116 2.020 0.153
        C_min 0.029 0.269 0.907 0.368
        C_max 0.018 0.152 1.986 0.324
        D_min 0.051 0.280 0.544 0.284
        D_max 0.022 0.221 1.853 0.935
        E_min 0.051 0.165 1.127 0.419
        E_max 0.053 0.142 1.785 0.839
        F_min 0.071 0.191 0.696 0.582
        F_max 0.041 0.164 1.734 0.922
        G_min 0.070 0.253 0.549 0.993
        G_max 0.046 0.129 1.764 0.994
    """
    for line in calibration.strip().splitlines():
        name, *vals = line.split()
        cases.append((name,) + tuple(float(v) for v in vals))
    # 12 random cases: draws in the order k1, k2, th, tau per case, each
    # rounded to 4 decimals so the CSV holds the exact inputs.
    rng = random.Random(20261121)
    for i in range(1, 13):
        k1 = round(rng.uniform(0.01, 1.0), 4)
        k2 = round(rng.uniform(0.01, 1.0), 4)
        th = round(rng.uniform(0.2, 3.0), 4)
        tau = round(rng.uniform(0.05, 1.0), 4)
        cases.append(("rand%02d" % i, k1, k2, th, tau))
    cases.append(("ode1", 0.3, 0.5, 1.2, 0.0))
    cases.append(("ode2", 0.1, 0.05, 2.0, 0.0))
    return cases


CALIBRATION_NAMES = [c + s for c in "ABCDEFG" for s in ("_min", "_max")]


def partials(k1, k2, th):
    """(f_s, f_v, f_l) as exact mp numbers from float inputs."""
    k1, k2, th = mpf(k1), mpf(k2), mpf(th)
    return k1, -(k1 * th + k2), k2


def zeta_of(frac):
    """zeta = exp(-2 pi i p/q) for frac = p/q, exact for 0 and 1/2."""
    x = mpf(2 * frac.numerator) / frac.denominator
    return mpc(mpmath.cospi(x), -mpmath.sinpi(x))


# ---------------------------------------------------------------------------
# Quasi-polynomials F(lam) = a2 lam^2 + a1 lam + a0 + (b1 lam + b0) e^{-lam tau}
# ---------------------------------------------------------------------------

class QP:
    def __init__(self, a2, a1, a0, b1, b0, tau, label=""):
        self.a2, self.a1, self.a0 = mpc(a2), mpc(a1), mpc(a0)
        self.b1, self.b0, self.tau = mpc(b1), mpc(b0), mpf(tau)
        self.label = label
        assert self.tau >= 0
        assert self.a2 in (0, 1)
        if self.a2 == 0:
            assert self.a1 == 1 and self.b1 == 0
        self.real = all(mpmath.im(c) == 0 for c in
                        (self.a2, self.a1, self.a0, self.b1, self.b0))
        # double-precision copies for the (fast) multistart Newton search
        self.c = tuple(complex(c) for c in (self.a2, self.a1, self.a0, self.b1, self.b0))
        self.ctau = float(self.tau)

    # 40-digit evaluation
    def f(self, z):
        e = mp.exp(-z * self.tau)
        return (self.a2 * z + self.a1) * z + self.a0 + (self.b1 * z + self.b0) * e

    def df(self, z):
        e = mp.exp(-z * self.tau)
        return 2 * self.a2 * z + self.a1 + (self.b1 - self.tau * (self.b1 * z + self.b0)) * e

    # double-precision evaluation (search only)
    def newton_double(self, z, maxit=100):
        a2, a1, a0, b1, b0 = self.c
        t = self.ctau
        try:
            for _ in range(maxit):
                e = cmath.exp(-z * t)
                fz = (a2 * z + a1) * z + a0 + (b1 * z + b0) * e
                dz = 2 * a2 * z + a1 + (b1 - t * (b1 * z + b0)) * e
                if dz == 0:
                    return None
                step = fz / dz
                z = z - step
                if not (abs(z) < 1e8):
                    return None
                if abs(step) <= 1e-13 * (1.0 + abs(z)):
                    return z
        except (OverflowError, ZeroDivisionError, ValueError):
            return None
        return None

    def bound(self, sigma):
        """Radius R with |lam| <= R for every root with Re(lam) >= sigma."""
        E = mp.exp(-mpf(sigma) * self.tau)
        if self.a2 == 1:
            b = abs(self.a1) + E * abs(self.b1)
            c = abs(self.a0) + E * abs(self.b0)
            return (b + mp.sqrt(b * b + 4 * c)) / 2
        return abs(self.a0) + E * abs(self.b0)

    def poly_coeffs(self):
        """Coefficients (highest first) when tau == 0."""
        assert self.tau == 0
        cs = [self.a2, self.a1 + self.b1, self.a0 + self.b0]
        while cs and cs[0] == 0:
            cs.pop(0)
        return cs


def ring_mode_qp(fs, fv, fl, tau, frac):
    if frac == 0:
        return QP(0, 1, -fv, 0, -fl, tau, "g")
    z = zeta_of(frac)
    return QP(1, -fv, 0, -z * fl, fs * (1 - z), tau, "mode %s" % frac)


def plant_qp(fs, fv, fl, tau):
    return QP(1, -fv, 0, 0, fs, tau, "plant")


# ---------------------------------------------------------------------------
# Argument principle
# ---------------------------------------------------------------------------

class NearContourRoot(Exception):
    pass


def _edge_phase(F, za, zb, hmax=mpf("0.5"), hmin=mpf("1e-9")):
    """Continuous change of arg F along the segment za -> zb (adaptive)."""
    L = abs(zb - za)
    u = (zb - za) / L
    s = mpf(0)
    f0 = F(za)
    if f0 == 0:
        raise NearContourRoot
    total = mpf(0)
    h = hmax
    lim = mp.pi / 8
    while L - s > L * mpf("1e-30"):
        h = min(h, L - s)
        last = (L - s) - h <= L * mpf("1e-30")
        fm = F(za + (s + h / 2) * u)
        f1 = F(zb if last else za + (s + h) * u)
        if fm == 0 or f1 == 0:
            raise NearContourRoot
        r1, r2 = fm / f0, f1 / fm
        d1, d2 = mp.arg(r1), mp.arg(r2)
        a1, a2 = abs(r1), abs(r2)
        if abs(d1) < lim and abs(d2) < lim and 0.5 < a1 < 2 and 0.5 < a2 < 2:
            total += d1 + d2
            s = L if last else s + h
            f0 = f1
            h = min(hmax, h * mpf("1.5"))
        else:
            h /= 2
            if h < hmin:
                raise NearContourRoot
    return total


def rectangle(qp, sigma):
    R = qp.bound(sigma)
    return mpf(sigma), R + 1, R + 1, R   # sigma, X (right), H (half height), R


def winding_count(qp, sigma, X, H):
    """Number of zeros of qp.f inside [sigma, X] x [-H, H] (argument principle)."""
    corners = [mpc(sigma, -H), mpc(X, -H), mpc(X, H), mpc(sigma, H)]
    total = mpf(0)
    for k in range(4):
        total += _edge_phase(qp.f, corners[k], corners[(k + 1) % 4])
    n = total / (2 * mp.pi)
    ni = int(mpmath.nint(n))
    if abs(n - ni) > mpf("1e-6"):
        raise RuntimeError("non-integer winding number %s for %s" % (n, qp.label))
    return ni


def quad_count(qp, sigma, X, H):
    """Same count from (1/2 pi i) * contour integral of F'/F (mpmath.quad).

    Each side is cut into pieces of length <= 1; a piece is bisected
    recursively while the quadrature error estimate exceeds 1e-10 (poles of
    F'/F close to the contour need short pieces).  Only an integer is
    needed, so 20 digits and a 1e-6 acceptance window suffice."""
    with mp.workdps(20):
        def g(z):
            return qp.df(z) / qp.f(z)

        def piece(za, zb, depth=0):
            v, err = mp.quad(g, [za, zb], error=True, maxdegree=6)
            if err < mpf("1e-10") or depth > 40:
                return v
            zm = (za + zb) / 2
            return piece(za, zm, depth + 1) + piece(zm, zb, depth + 1)

        corners = [mpc(sigma, -H), mpc(X, -H), mpc(X, H), mpc(sigma, H)]
        total = mpc(0)
        for k in range(4):
            za, zb = corners[k], corners[(k + 1) % 4]
            n = int(mpmath.ceil(abs(zb - za)))
            for j in range(n):
                total += piece(za + (zb - za) * j / n, za + (zb - za) * (j + 1) / n)
        val = total / (2j * mp.pi)
        ni = int(mpmath.nint(val.real))
        assert abs(val - ni) < mpf("1e-6"), (qp.label, sigma, val)
        return ni


def count_with_shift(qp, sigma):
    """Count roots with Re > sigma'; sigma' = sigma unless a root is too close."""
    shift = mpf(0)
    for _ in range(10):
        s = mpf(sigma) - shift
        sg, X, H, R = rectangle(qp, s)
        try:
            return s, X, H, R, winding_count(qp, sg, X, H)
        except NearContourRoot:
            shift += mpf("0.0137")
    raise RuntimeError("could not place contour for %s" % qp.label)


# ---------------------------------------------------------------------------
# Root search
# ---------------------------------------------------------------------------

def polish(qp, z0):
    try:
        z = mpmath.findroot(qp.f, mpc(z0), solver="newton", df=qp.df, maxsteps=60)
    except (ValueError, ZeroDivisionError):
        return None
    z = mpc(z)
    if qp.real and abs(z.imag) < mpf("1e-30") * (1 + abs(z)):
        # real-coefficient function and a root real to 1e-30: its conjugate
        # would coincide with it at 1e-20, so the root is real.
        z = mpmath.findroot(lambda x: qp.f(mpc(x, 0)).real, z.real,
                            solver="newton", df=lambda x: qp.df(mpc(x, 0)).real,
                            maxsteps=60)
        z = mpc(z, 0)
    return z


def find_all(qp, sigma, X, H, count, info):
    """All roots inside [sigma, X] x [-H, H]; must number `count`."""
    width, height = float(X - sigma), float(2 * H)
    d = max(0.25, min(1.5, math.sqrt(width * height / 2500.0)))
    for refine in range(5):
        nx = max(8, int(math.ceil(width / d)))
        ny = max(8, int(math.ceil(height / d)))
        approx = []
        s0, h0 = float(sigma), float(H)
        for i in range(nx):
            x = s0 + (i + 0.5) * width / nx
            for j in range(ny):
                y = -h0 + (j + 0.5) * height / ny
                z = qp.newton_double(complex(x, y))
                if z is None:
                    continue
                if z.real <= s0 - 1e-6 or z.real > float(X) or abs(z.imag) > h0:
                    continue
                if all(abs(z - w) > 1e-7 * (1 + abs(z)) for w in approx):
                    approx.append(z)
        roots = []
        for z0 in approx:
            z = polish(qp, z0)
            if z is None or not (z.real > sigma and z.real < X and abs(z.imag) < H):
                continue
            if all(abs(z - w) > DEDUP_REL * max(1, abs(z)) for w in roots):
                roots.append(z)
        if len(roots) == count:
            info["grid_refinements"] = refine
            info["grid_points"] = nx * ny
            return roots
        info.setdefault("mismatch_log", []).append(
            "%s sigma=%s: count=%d found=%d with %dx%d grid" %
            (qp.label, mpmath.nstr(sigma, 6), count, len(roots), nx, ny))
        d /= 2
    raise RuntimeError("root count mismatch for %s: %s" % (qp.label, info["mismatch_log"]))


def sort_roots(roots):
    """Largest real part first; ties (to 1e-30) broken by larger imaginary part."""
    def cmp(a, b):
        if abs(a.real - b.real) > TIE_TOL * max(1, abs(a), abs(b)):
            return -1 if a.real > b.real else 1
        if a.imag != b.imag:
            return -1 if a.imag > b.imag else 1
        return 0
    return sorted(roots, key=functools.cmp_to_key(cmp))


def rightmost_roots(qp, need):
    """All roots with Re > sigma, sigma = first of SIGMA_LIST with >= need roots."""
    info = {"label": qp.label}
    cache = {}
    k = 0
    for k, sig in enumerate(SIGMA_LIST):
        if k > 0 and qp.bound(sig) > R_CAP:     # rectangle would be absurdly large
            k -= 1
            info["capped"] = True
            break
        cache[k] = count_with_shift(qp, sig)
        if cache[k][4] >= need:
            break
    # monotonicity of the counts (sanity check of the argument principle)
    ks = sorted(cache)
    for i, j in zip(ks, ks[1:]):
        assert cache[i][4] <= cache[j][4], (qp.label, cache)
    sigma, X, H, R, n = cache[k]
    roots = find_all(qp, sigma, X, H, n, info) if n > 0 else []
    for z in roots:
        assert abs(z) <= R * (1 + mpf("1e-30")), (qp.label, z, R)
    # second, independent evaluation of the final count: contour integral of F'/F
    nq = quad_count(qp, sigma, X, H)
    assert nq == n == len(roots), (qp.label, n, nq, len(roots))
    info.update(sigma=sigma, R=R, count=n, quad_count=nq, counts_evaluated=len(cache))
    if info.get("capped") and n >= need:
        del info["capped"]               # the cap did not limit the result
    if qp.tau == 0:
        # polynomial: cross-check against mpmath.polyroots and report its values
        pr = mpmath.polyroots(qp.poly_coeffs(), maxsteps=200, extraprec=200)
        pr = [mpc(p) for p in (pr if isinstance(pr, list) else [pr])]
        inside = [p for p in pr if p.real > sigma]
        assert len(inside) == len(roots), (qp.label, pr, roots)
        for p in inside:
            assert min(abs(p - z) for z in roots) < mpf("1e-30"), (qp.label, p, roots)
        info["polyroots_all"] = pr
        roots = [mpc(z.real, 0) if qp.real and abs(z.imag) < mpf("1e-30") else z
                 for z in inside]
    if qp.real:
        # real coefficients: make conjugate pairs exactly symmetric
        upper = [z for z in roots if z.imag > 0]
        lower = [z for z in roots if z.imag < 0]
        assert len(upper) == len(lower), (qp.label, roots)
        for z in upper:
            assert min(abs(mpmath.conj(z) - w) for w in lower) < mpf("1e-25"), (qp.label, z)
        roots = ([z for z in roots if z.imag == 0] + upper +
                 [mpmath.conj(z) for z in upper])
    for z in roots:
        res = abs(qp.f(z))
        assert res < RESIDUAL_TOL, (qp.label, z, res)
    return sort_roots(roots), info


# ---------------------------------------------------------------------------
# String stability quantities
# ---------------------------------------------------------------------------

def golden_max(fun, a, b, rel=mpf("1e-30")):
    """Golden-section search for a maximum of fun on [a, b]."""
    g = (mp.sqrt(5) - 1) / 2
    c, d = b - g * (b - a), a + g * (b - a)
    fc, fd = fun(c), fun(d)
    while b - a > rel * b:
        if fc >= fd:
            b, d, fd = d, c, fc
            c = b - g * (b - a)
            fc = fun(c)
        else:
            a, c, fc = c, d, fd
            d = a + g * (b - a)
            fd = fun(d)
    return (a + b) / 2


def string_quantities(fs, fv, fl, tau, plant_roots):
    tau = mpf(tau)

    def D(s):
        return s * s - fv * s + fs * mp.exp(-s * tau)

    def Nn(s):
        return (fs + fl * s) * mp.exp(-s * tau)

    def P(w):
        return fs * fs + fl * fl * w * w

    def Q(w):
        return (w ** 4 + (fv * fv - 2 * fs * mp.cos(w * tau)) * w * w
                + 2 * fv * fs * w * mp.sin(w * tau) + fs * fs)

    def dP(w):
        return 2 * fl * fl * w

    def dQ(w):
        c, s = mp.cos(w * tau), mp.sin(w * tau)
        return (4 * w ** 3 + 2 * fv * fv * w - 4 * fs * w * c + 2 * fs * tau * w * w * s
                + 2 * fv * fs * s + 2 * fv * fs * tau * w * c)

    def G2(w):
        return P(w) / Q(w)

    def slope(w):           # sign of d(P/Q)/dw
        return dP(w) * Q(w) - P(w) * dQ(w)

    # verify the closed forms of P and Q (and dQ) against the complex expressions
    for w in (mpf("0.013"), mpf("0.37"), mpf("1.9"), mpf("7.5")):
        s = mpc(0, w)
        assert abs(abs(D(s)) ** 2 - Q(w)) < mpf("1e-32") * (1 + Q(w))
        assert abs(abs(Nn(s)) ** 2 - P(w)) < mpf("1e-32") * (1 + P(w))
        assert abs(mpmath.diff(Q, w) - dQ(w)) < mpf("1e-25") * (1 + abs(dQ(w)))

    # c2 and its numerical verification
    c2 = fv * fv + 2 * fv * fs * tau - 2 * fs - fl * fl
    w = mpf("1e-10")
    s = mpc(0, w)
    q = (abs(D(s)) ** 2 - abs(Nn(s)) ** 2) / (w * w)
    assert abs(q - c2) < mpf("1e-15") * (1 + abs(c2)), (q, c2)
    tay = mpmath.taylor(lambda x: abs(D(mpc(0, x))) ** 2 - abs(Nn(mpc(0, x))) ** 2, 0, 2)
    assert abs(tay[0]) < mpf("1e-25") and abs(tay[1]) < mpf("1e-15")
    assert abs(tay[2] - c2) < mpf("1e-12") * (1 + abs(c2)), (tay, c2)
    # c2 also equals 2 k1 (k1 th^2/2 + k2 th - 1 - tau (k1 th + k2)) (algebra:
    # expand f_v^2 with f_s = k1, f_v = -(k1 th + k2), f_l = k2); consistency check only
    k1, k2 = fs, fl
    th = (-fv - k2) / k1
    alt = 2 * k1 * (k1 * th * th / 2 + k2 * th - 1 - tau * (k1 * th + k2))
    assert abs(alt - c2) < mpf("1e-30"), (alt, c2)

    # upper frequency W: bound B(w) < 1/2 and decreasing on [W, inf)
    a, b = abs(fs), abs(fl)
    cc, dd = abs(fv), abs(fs)

    def B(w):
        den = w * w - cc * w - dd
        return mpmath.inf if den <= 0 else (a + b * w) / den
    # dB/dw has the sign of -b w^2 - 2 a w + (a cc - b dd): negative beyond its root
    if b > 0:
        disc = 4 * a * a + 4 * b * (a * cc - b * dd)
        w_dec = (-2 * a + mp.sqrt(disc)) / (2 * b) if disc > 0 else mpf(0)
    else:
        w_dec = cc / 2
    W = mpf(1)
    while B(W) >= 0.5 or W <= w_dec or W * W - cc * W - dd <= 0:
        W *= 2

    # sampling grid (log-spaced) plus plant-root frequencies
    w_lo = mpf("1e-4")
    n_grid = 20000
    while True:
        lw0, lw1 = mp.log(w_lo), mp.log(W)
        grid = [mp.exp(lw0 + (lw1 - lw0) * j / (n_grid - 1)) for j in range(n_grid)]
        extra = [z.imag for z in plant_roots if w_lo < z.imag < W]
        grid = sorted(set(grid + extra))
        vals = [G2(x) for x in grid]
        imax = max(range(len(vals)), key=lambda i: vals[i])
        if imax == 0 and c2 < 0:      # peak below w_lo: extend grid downwards
            w_lo /= 100
            continue
        break

    peaks = []
    for i in range(1, len(grid) - 1):
        if vals[i] >= vals[i - 1] and vals[i] >= vals[i + 1]:
            lo, hi = grid[i - 1], grid[i + 1]
            slo, shi = slope(lo), slope(hi)
            if slo > 0 and shi < 0:
                for _ in range(400):          # bisection on the slope sign
                    mid = (lo + hi) / 2
                    if slope(mid) > 0:
                        lo = mid
                    else:
                        hi = mid
                    if hi - lo < mpf("1e-36") * hi:
                        break
                wp = (lo + hi) / 2
            else:                             # flat / degenerate sample: golden section
                wp = golden_max(G2, lo, hi)
            assert grid[i - 1] <= wp <= grid[i + 1]
            assert G2(wp) >= max(vals[i - 1], vals[i], vals[i + 1]) * (1 - mpf("1e-30"))
            peaks.append((G2(wp), wp))
    info = {"n_local_max": len(peaks), "W": W, "w_lo": w_lo}
    best = max(peaks, key=lambda p: p[0]) if peaks else None
    if best is not None and (best[0] > 1 or c2 < 0):
        sup, wpk = mp.sqrt(best[0]), best[1]
    else:
        # supremum approached only as w -> 0: |Gamma(iw)| < 1 near 0 and decreasing
        assert c2 > 0 and vals[0] < 1 and vals[0] > vals[1], "unexpected shape"
        sup, wpk = mpf(1), mpf(0)
    for v in vals:
        assert mp.sqrt(v) <= sup * (1 + mpf("1e-30"))
    info["peaks"] = peaks
    return c2, sup, wpk, info


# ---------------------------------------------------------------------------
# Work units (run in a process pool)
# ---------------------------------------------------------------------------

def task_ring(args):
    name, k1, k2, th, tau, frac = args
    fs, fv, fl = partials(k1, k2, th)
    qp = ring_mode_qp(fs, fv, fl, mpf(tau), frac)
    t0 = time.time()
    roots, info = rightmost_roots(qp, ROOTS_PER_MODE)
    info["time"] = time.time() - t0
    return ("ring", name, frac, roots, info)


def task_string(args):
    name, k1, k2, th, tau = args
    fs, fv, fl = partials(k1, k2, th)
    qp = plant_qp(fs, fv, fl, mpf(tau))
    t0 = time.time()
    roots, info = rightmost_roots(qp, 1)
    assert roots, name
    abscissa = max(z.real for z in roots)
    c2, sup, wpk, sinfo = string_quantities(fs, fv, fl, mpf(tau), roots)
    info.update(sinfo)
    info["time"] = time.time() - t0
    return ("string", name, None, (roots, abscissa, c2, sup, wpk), info)


def run_task(task):
    kind, args = task
    return task_ring(args) if kind == "ring" else task_string(args)


# ---------------------------------------------------------------------------
# Self-checks that do not depend on the cases
# ---------------------------------------------------------------------------

def lambert_check():
    """lam = a e^{-lam tau}, a=-1, tau=1: roots are W_k(a tau)/tau."""
    a, tau = mpf(-1), mpf(1)
    qp = QP(0, 1, 0, 0, -a, tau, "lambert")
    roots, info = rightmost_roots(qp, 2)
    sigma = info["sigma"]
    expected = [mpmath.lambertw(a * tau, k) / tau for k in range(-60, 61)]
    expected = [z for z in expected if z.real > sigma]
    assert info["count"] == len(expected) == len(roots), (info, expected)
    assert abs(roots[0] - mpmath.lambertw(a * tau, 0) / tau) < mpf("1e-30")
    assert abs(roots[1] - mpmath.lambertw(a * tau, -1) / tau) < mpf("1e-30")
    for z in expected:
        assert min(abs(z - r) for r in roots) < mpf("1e-30")
    # the count also via the contour integral of F'/F, on a larger rectangle
    s2 = mpf(-4)
    sg, X, H, R = rectangle(qp, s2)
    n_w = winding_count(qp, sg, X, H)
    n_q = quad_count(qp, sg, X, H)
    n_e = len([k for k in range(-200, 201)
               if (mpmath.lambertw(a * tau, k) / tau).real > s2])
    assert n_w == n_q == n_e, (n_w, n_q, n_e)
    return roots, info, (n_w, n_q, n_e)


def conjugate_and_factor_checks(cases):
    """Mode N-m = conj(mode m); f_0(lam) = lam * g(lam); quad-count cross-check."""
    name, k1, k2, th, tau = cases[0]
    fs, fv, fl = partials(k1, k2, th)
    tau = mpf(tau)
    r2, _ = rightmost_roots(ring_mode_qp(fs, fv, fl, tau, Fraction(2, 5)), 3)
    r3, _ = rightmost_roots(ring_mode_qp(fs, fv, fl, tau, Fraction(3, 5)), 3)
    assert len(r2) == len(r3)
    for z in r2:
        assert min(abs(mpmath.conj(z) - w) for w in r3) < mpf("1e-30")
    g = ring_mode_qp(fs, fv, fl, tau, Fraction(0))
    lam = mpc("0.3", "-1.7")
    f0 = lam * lam - fv * lam + fs * mp.exp(-lam * tau) - mp.exp(-lam * tau) * (fs + fl * lam)
    assert abs(f0 - lam * g.f(lam)) < mpf("1e-35")
    # argument principle by quadrature equals the winding count
    results = []
    for qp in (ring_mode_qp(fs, fv, fl, tau, Fraction(1, 5)), plant_qp(fs, fv, fl, tau)):
        sg, X, H, R = rectangle(qp, -3)
        n_w, n_q = winding_count(qp, sg, X, H), quad_count(qp, sg, X, H)
        assert n_w == n_q, (qp.label, n_w, n_q)
        results.append((qp.label, n_w, n_q))
    return results


# ---------------------------------------------------------------------------
# Output helpers
# ---------------------------------------------------------------------------

def d17(x):
    """Correctly rounded binary64 value of x, printed with 17 significant digits."""
    v = float(mpf(x))   # mpf -> float rounds to nearest
    if v == 0:
        v = 0.0         # no negative zero
    return "%.17g" % v


def inp(x):
    """Input parameter in shortest round-trip form."""
    return repr(float(x))


# ---------------------------------------------------------------------------
# Main
# ---------------------------------------------------------------------------

def main():
    t_start = time.time()
    cases = build_cases()
    print("cases:")
    for c in cases:
        print("  %-14s k1=%-7s k2=%-7s th=%-7s tau=%s" % c)

    # unique ring problems: (case, reduced fraction m/N)
    fracs = sorted({Fraction(m, N) for N in RING_SIZES for m in range(N // 2 + 1)})
    tasks = []
    for c in cases:
        tasks.append(("string", c))
    for c in cases:
        for fr in fracs:
            tasks.append(("ring", c + (fr,)))
    print("%d work units (%d ring problems) on %d processes" %
          (len(tasks), len(tasks) - len(cases), PROCESSES))

    ring, string = {}, {}
    done = 0
    with Pool(PROCESSES) as pool:
        for kind, name, frac, payload, info in pool.imap_unordered(run_task, tasks, chunksize=1):
            if kind == "ring":
                ring[(name, frac)] = (payload, info)
            else:
                string[name] = (payload, info)
            done += 1
            if done % 100 == 0:
                print("  %d/%d done (%.0f s)" % (done, len(tasks), time.time() - t_start))
                sys.stdout.flush()
    t_main = time.time() - t_start
    print("main computation: %.1f s" % t_main)

    # ---- self checks independent of cases
    lam_roots, lam_info, lam_counts = lambert_check()
    print("Lambert-W check ok: rightmost roots %s, %s; count(Re > %s) = %d; "
          "counts at sigma=-4 (winding, quad, branches) = %s" %
          (mpmath.nstr(lam_roots[0], 20), mpmath.nstr(lam_roots[1], 20),
           mpmath.nstr(lam_info["sigma"], 4), lam_info["count"], lam_counts))
    print("conjugate/factorisation/quad-count checks ok:", conjugate_and_factor_checks(cases))

    # ---- ring roots CSV
    n_rows = 0
    short_modes = []
    mismatches = []
    os.makedirs(os.path.dirname(OUT_RING), exist_ok=True)
    max_res = mpf(0)
    with open(OUT_RING, "w") as fh:
        fh.write("case,k1,k2,th,tau,N,mode,rank,re,im\n")
        for (name, k1, k2, th, tau) in cases:
            fs, fv, fl = partials(k1, k2, th)
            for N in RING_SIZES:
                for m in range(N // 2 + 1):
                    fr = Fraction(m, N)
                    roots, info = ring[(name, fr)]
                    mismatches += info.get("mismatch_log", [])
                    # residual check (a) against the ORIGINAL f_m (g for mode 0)
                    z_m = zeta_of(fr)
                    for z in roots:
                        e = mp.exp(-z * mpf(tau))
                        if m == 0:
                            res = abs(z - fv - fl * e)
                        else:
                            res = abs(z * z - fv * z + fs * e - z_m * e * (fs + fl * z))
                        assert res < RESIDUAL_TOL, (name, N, m, z, res)
                        max_res = max(max_res, res)
                    top = roots[:ROOTS_PER_MODE]
                    if len(top) < ROOTS_PER_MODE:
                        short_modes.append((name, N, m, len(top), info["sigma"]))
                    for rank, z in enumerate(top):
                        fh.write("%s,%s,%s,%s,%s,%d,%d,%d,%s,%s\n" %
                                 (name, inp(k1), inp(k2), inp(th), inp(tau), N, m, rank,
                                  d17(z.real), d17(z.imag)))
                        n_rows += 1
    print("wrote %s (%d rows), max residual %s" % (OUT_RING, n_rows, mpmath.nstr(max_res, 3)))

    # ---- string CSV
    with open(OUT_STRING, "w") as fh:
        fh.write("case,k1,k2,th,tau,plant_abscissa,sup_gamma,omega_peak,c2\n")
        for (name, k1, k2, th, tau) in cases:
            (roots, absc, c2, sup, wpk), info = string[name]
            mismatches += info.get("mismatch_log", [])
            fh.write("%s,%s,%s,%s,%s,%s,%s,%s,%s\n" %
                     (name, inp(k1), inp(k2), inp(th), inp(tau),
                      d17(absc), d17(sup), d17(wpk), d17(c2)))
    print("wrote %s (%d rows)" % (OUT_STRING, len(cases)))

    # ---- diagnostics
    print("\nstring quantities:")
    for (name, k1, k2, th, tau) in cases:
        (roots, absc, c2, sup, wpk), info = string[name]
        print("  %-14s abscissa=%-12s sup|Gamma|=%-12s w_peak=%-12s c2=%-12s "
              "(plant sigma=%s, roots=%d, local maxima=%d, W=%s)" %
              (name, mpmath.nstr(absc, 8), mpmath.nstr(sup, 8), mpmath.nstr(wpk, 8),
               mpmath.nstr(c2, 8), mpmath.nstr(info["sigma"], 4), info["count"],
               info["n_local_max"], mpmath.nstr(info["W"], 4)))

    print("\ncalibration settings (paper: all string unstable):")
    bad = []
    for name in CALIBRATION_NAMES:
        (roots, absc, c2, sup, wpk), info = string[name]
        ok = c2 < 0 and sup > 1
        if not ok:
            bad.append(name)
        print("  %-6s c2=%-14s sup=%-14s %s" % (name, mpmath.nstr(c2, 8), mpmath.nstr(sup, 10),
                                             "ok" if ok else "NOT string unstable"))
    if bad:
        print("WARNING: calibration settings not string unstable:", bad)

    print("\nroot-count / search diagnostics:")
    print("  count/found disagreements resolved by grid refinement: %d" % len(mismatches))
    for line in mismatches:
        print("    " + line)
    refinements = [(k, v[1]["grid_refinements"]) for k, v in ring.items()
                   if v[1].get("grid_refinements")]
    print("  ring problems that needed grid refinement: %d" % len(refinements))
    capped = [k for k, v in ring.items() if v[1].get("capped")]
    print("  ring problems where the R cap stopped the sigma search: %d %s" % (len(capped), capped))
    sig = {}
    for k, v in ring.items():
        sig.setdefault(mpmath.nstr(v[1]["sigma"], 6), []).append(k)
    print("  final sigma used (ring problems): " +
          ", ".join("%s: %d" % (s, len(v)) for s, v in sorted(sig.items(), key=lambda t: -float(t[0]))))
    maxR = max(float(v[1]["R"]) for v in ring.values())
    print("  largest rectangle radius R: %.2f" % maxR)
    slow = sorted(ring.items(), key=lambda kv: -kv[1][1]["time"])[:5]
    print("  slowest ring problems: " +
          ", ".join("%s %s %.1fs" % (k[0], k[1], v[1]["time"]) for k, v in slow))
    print("  modes with fewer than %d roots with Re > sigma (reported rows = roots found): %d"
          % (ROOTS_PER_MODE, len(short_modes)))
    by_case = {}
    for name, N, m, n, s in short_modes:
        by_case.setdefault(name, []).append((N, m, n, mpmath.nstr(s, 4)))
    for name, lst in by_case.items():
        print("    %-14s %d modes, e.g. %s" % (name, len(lst), lst[:3]))

    print("\ntotal run time: %.1f s" % (time.time() - t_start))


if __name__ == "__main__":
    main()
