"""ddemap: stability of delay differential equations in car-following traffic, from Python.

Each function mirrors one command of the ``ddemap`` program: the same library calls, the
command's options as keyword arguments (``--seed-grid`` is ``seed_grid``, ``--t-end`` is
``t_end``), in the same units, with the same defaults. Model parameters are keyword arguments
by name, in the units of the model table:

    k1 [1/s^2]  gain on the gap error          k2 [1/s]  gain on the speed difference
    th [s]      time headway                   tau [s]   actuation/sensing delay
    eta [m]     standstill distance            speed [m/s] equilibrium speed
    a, b [m/s^2], v0 [m/s], delta: IDM (model="idm")

A ring size ``ring`` is an integer N >= 2 (N cars on a ring road, analysed through the Fourier
modes zeta = exp(-2 pi i m / N)) or ``"inf"`` (every wave number).

Every function returns a :class:`Result`: a dict with the keys of the command's JSON
``result`` (``ddemap COMMAND --format json``), lists of numbers as NumPy arrays and lists of
records (e.g. the roots) as a dict of NumPy columns; JSON null becomes NaN in a numeric
column. The envelope's ``status``, ``message``, ``inputs``, ``solver`` and ``version`` are
attributes. ``status`` is ``"converged"`` or the reason a result is not trusted: as in the
command line, a computation that did not converge is a status, not an exception.

Bad input raises ValueError with the library's message. Every computation runs with the GIL
released. Ctrl-C (KeyboardInterrupt) stops ``sweep`` and ``boundary`` between grid rows,
``classify`` between vehicles (and parameter samples), ``simulate`` between steps,
``calibrate`` between fits, ``equilibria`` and ``hopf`` between the points of a branch or a
Hopf curve, ``orbits`` between orbits, and ``roots``/``string`` with a ring between the modes
of the per-mode path, ``roots`` of a ``system`` and ``mixed_ring`` between the steps of the root
search; the winding pass and one dense collocation degree (each well under a second to a few
seconds) finish first.

Quick start (the paper's stability chart)::

    import ddemap
    r = ddemap.sweep(th=1.5, tau=0.1, k1=(0.01, 1, 100), k2=(0.01, 1, 100))
    r["grid"]["region"]   # 0 plant unstable, 1 ring unstable, 2 string unstable, 3 string stable
"""

import json as _json
import math as _math
import os as _os

import numpy as _np

from . import _ddemap

__all__ = ["__version__", "Result", "roots", "string", "sweep", "boundary", "classify", "simulate", "calibrate",
           "mixed_ring", "equilibria", "hopf", "orbits", "version"]

version = _ddemap.version
__version__ = _ddemap.version


class Result(dict):
    """A command's result: a dict of the JSON ``result`` keys, with the envelope as attributes.

    Attributes: ``command``, ``version``, ``inputs`` (the parsed inputs, defaults filled in),
    ``solver`` (``{"given", "used"}`` or None), ``status`` (``"converged"`` or why not) and
    ``message`` (why the result is trusted, or why not).
    """

    command = ""
    version = ""
    inputs = None
    solver = None
    status = ""
    message = ""

    @property
    def converged(self):
        """True when ``status`` is ``"converged"``."""
        return self.status == "converged"

    def __repr__(self):
        return "Result(command=%r, status=%r, keys=%r)" % (self.command, self.status, sorted(self.keys()))


# ------------------------------------------------------------------ conversion


def _is_number(v):
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def _column(values):
    """A list of JSON values as a NumPy array where they are all numbers (None -> NaN) or all
    booleans, a dict of columns where they are records with the same keys; otherwise a list of
    converted values."""
    if values and all(isinstance(v, dict) for v in values) and all(v.keys() == values[0].keys() for v in values):
        return {k: _column([v[k] for v in values]) for k in values[0]}
    if values and all(v is None or _is_number(v) for v in values) and any(v is not None for v in values):
        if all(isinstance(v, int) for v in values):
            return _np.array(values, dtype=_np.int64)
        return _np.array([_math.nan if v is None else v for v in values], dtype=float)
    if values and all(isinstance(v, bool) for v in values):
        return _np.array(values, dtype=bool)
    return [_convert(v) for v in values]


def _convert(value):
    """JSON value -> Python: lists of numbers as arrays, lists of records as dicts of columns."""
    if isinstance(value, dict):
        return {k: _convert(v) for k, v in value.items()}
    if isinstance(value, list):
        return _column(value)
    return value


def _result(envelope_text):
    e = _json.loads(envelope_text)
    r = Result(_convert(e["result"]))
    r.command = e["command"]
    r.version = e["version"]
    r.inputs = e["inputs"]
    r.solver = e["solver"]
    r.status = e["status"]
    r.message = e["message"]
    return r


# ------------------------------------------------------------------ arguments


def _ring(ring, allow_inf=True):
    """ring: N >= 2, or "inf" / math.inf -> 0 (the library's code for infinity)."""
    if allow_inf and (ring in ("inf", "infinity") or (isinstance(ring, float) and _math.isinf(ring) and ring > 0)):
        return 0
    if isinstance(ring, bool) or not isinstance(ring, (int, _np.integer)) or not 2 <= ring <= 1000000:
        expected = "an integer N >= 2 (at most 1000000)" + (" or 'inf'" if allow_inf else "; this ring is finite")
        raise ValueError("ring = %r: expected %s" % (ring, expected))
    return int(ring)


def _number(name, value):
    if isinstance(value, bool) or not isinstance(value, (int, float, _np.integer, _np.floating)) or not _math.isfinite(value):
        raise ValueError("%s = %r: expected a finite number" % (name, value))
    return float(value)


def _integer(name, value, lo, hi):
    if isinstance(value, bool) or not isinstance(value, (int, _np.integer)) or not lo <= value <= hi:
        raise ValueError("%s = %r: expected an integer between %d and %d" % (name, value, lo, hi))
    return int(value)


def _parameters(parameters):
    return {name: _number(name, v) for name, v in parameters.items()}


def _axes(parameters, x, counts):
    """Splits model parameters into fixed values and the two swept axes (tuples). The axes are
    returned as (name, "LO:HI:COUNT") in the library's syntax, x first (default: alphabetical,
    as the command line)."""
    fixed, axes = {}, []
    for name in sorted(parameters):
        v = parameters[name]
        if isinstance(v, (tuple, list)):
            if len(v) != (3 if counts else 2):
                raise ValueError("%s = %r: expected %s" % (name, v, "(LO, HI, COUNT)" if counts else "(LO, HI)"))
            lo, hi = _number(name, v[0]), _number(name, v[1])
            count = v[2] if counts else None
            if counts and (isinstance(count, bool) or not isinstance(count, (int, _np.integer))):
                raise ValueError("%s = %r: expected an integer COUNT in (LO, HI, COUNT)" % (name, v))
            axes.append((name, lo, hi, count))
        else:
            fixed[name] = _number(name, v)
    if len(axes) != 2:
        raise ValueError("expected exactly two swept parameters given as %s (e.g. k1=%s, k2=%s), got %d"
                         % ("(LO, HI, COUNT)" if counts else "(LO, HI)",
                            "(0.01, 1, 200)" if counts else "(0.01, 1)", "(0.01, 1, 200)" if counts else "(0.01, 1)", len(axes)))
    if x is not None:
        if axes[1][0] == x:
            axes.reverse()
        if axes[0][0] != x:
            raise ValueError("x = %r: expected one of the swept parameters" % (x,))
    return fixed, axes


def _text(v):
    """A number as the shortest text that reads back to it (1.0 as "1", as typed on a command line)."""
    t = repr(float(v))
    return t[:-2] if t.endswith(".0") else t


def _axis_text(axis, grid):
    name, lo, hi, count = axis
    return name, "%s:%s:%d" % (_text(lo), _text(hi), count if count is not None else grid)


# ------------------------------------------------------------------ commands


def roots(model="ovrv", ring=22, count=6, system=None, solver="auto", degree=0, **parameters):
    """Rightmost characteristic roots of a ring of ``ring`` identical cars (``ddemap roots``),
    or of any linear DDE ``x' = A0 x + sum_k A_k x(t - tau_k)`` from a JSON file
    (``system=FILE``, ``roots --system``; a nonlinear system file is linearised at its
    equilibrium, found by Newton from the file's guess).

    The linearisation of the car-following law about the equilibrium gives, per ring mode m
    (zeta = exp(-2 pi i m / N)), the quasi-polynomial
    ``lambda^2 - lambda own(lambda) + gap(lambda) - zeta (gap(lambda) + lambda lead(lambda))``
    whose roots are computed by Chebyshev collocation and refined by Newton. The root 0 of
    mode 0 (ring-length invariance) is excluded from every verdict.

    Keyword arguments: ``model`` ("ovrv", "idm", "ccc"), its parameters (k1 [1/s^2], k2 [1/s],
    th [s], tau [s], eta [m], ...), ``ring`` (N >= 2 or "inf"), ``count`` (how many roots).

    With ``system``: ``solver`` "auto" (dense up to 16 states), "dense" or "sparse"
    (shift-invert Arnoldi) and ``degree`` M (sparse path; 0 automatic); no model parameters.

    Returns: ``roots`` (columns ``re``, ``im`` [1/s], ``mode``, ``theta`` [rad], ``residual``,
    ``newton_step``), ``spectral_abscissa`` [1/s] (max Re, trivial zero excluded),
    ``abscissa_mode``, ``ring_stable``, ``ring_margin`` (= -abscissa), ``unstable_roots``,
    ``marginal_roots``, ``trivial_root``, ``degree`` (collocation degree M), ``degree_reason``;
    with ``system`` the keys of ``roots --system`` (``equilibrium`` and ``linearisation`` for
    a nonlinear file).
    """
    count = _integer("count", count, 1, 10000)
    if system is not None:
        if parameters or model != "ovrv" or ring != 22:
            raise ValueError("system takes the whole problem from the file: expected no model parameters, model or ring")
        degree = _integer("degree", degree, 0, 200)
        if degree == 1:
            raise ValueError("degree = 1: expected 0 (automatic) or an integer 2..200")
        return _result(_ddemap.roots_system(str(system), count, degree, solver))
    if solver != "auto" or degree != 0:
        raise ValueError("solver and degree go with system (and mixed_ring); a ring of identical cars has one method")
    return _result(_ddemap.roots(model, _parameters(parameters), _ring(ring), count))


def string(model="ovrv", ring=None, **parameters):
    """Plant and string stability of identical cars (``ddemap string``).

    Gamma(s) = (gap(s) + s lead(s)) / (s^2 - s own(s) + gap(s)) is the transfer function from
    the speed of the car ahead to the car's own speed. The plant is stable when every root of
    the denominator has Re < 0; the platoon is string stable when moreover
    sup_{w > 0} |Gamma(iw)| <= 1, the low-frequency limit decided exactly by the series
    |D|^2 - |N|^2 = c2 w^2 + c4 w^4 + ... (c2 < 0: amplifies as w -> 0).

    Keyword arguments: ``model`` and its parameters (see :func:`roots`); ``ring`` (N or "inf"):
    also decide ring stability.

    Returns: ``plant_stable``, ``plant_abscissa`` [1/s], ``plant_margin``, ``sup_gamma``,
    ``omega_peak`` [rad/s] (0 when the sup 1 is only approached as w -> 0), ``peak_margin``,
    ``lowfreq_margin`` (the decisive coefficient), ``lowfreq`` (c2 [s^2], c4, c6, c8),
    ``string_stable``, ``peaks``; with ``ring`` also ``ring_stable``, ``spectral_abscissa``,
    ``ring_margin``.
    """
    return _result(_ddemap.string(model, _parameters(parameters), None if ring is None else _ring(ring)))


def sweep(model="ovrv", ring=22, x=None, boundaries=True, ring_curves="auto", **parameters):
    """A stability chart over two model parameters (``ddemap sweep``).

    Give exactly two parameters as ``(LO, HI, COUNT)`` (the axes, COUNT >= 2 grid points from
    LO to HI inclusive) and the others as numbers, e.g.
    ``sweep(th=1.5, tau=0.1, k1=(0.01, 1, 200), k2=(0.01, 1, 200))``. ``x`` names the horizontal
    axis (default: the alphabetically first). At each grid point the rightmost root of every
    ring mode and of the plant is continued along the rows and certified by the argument
    principle; the string-stability quantities are those of :func:`string`. ``boundaries``:
    also trace the stability boundaries by continuation; ``ring_curves``: "all" (every ring
    mode's Hopf curve), "envelope" (only the boundary of the ring-stable region, any ring size)
    or "auto" (all up to 64 cars), as ``--ring-curves``. Runs in parallel (OMP_NUM_THREADS);
    the result does not depend on the number of threads.

    Returns the keys of the command's JSON (``regions``, ``points``, ``degree``, ``fallbacks``,
    ``uncertified_points``, ``seconds``, ...; ``x`` and ``y`` describe the axes and also hold
    ``values``, the grid coordinates), and:

    * ``grid``: one array of shape (y count, x count) per quantity (the CSV's columns):
      ``spectral_abscissa`` [1/s], ``unstable_roots``, ``sup_gamma``, ``omega_peak`` [rad/s],
      ``plant_stable``, ``ring_stable``, ``string_stable``, ``abscissa_mode``,
      ``plant_abscissa`` [1/s], ``lowfreq_margin`` (c2), ``peak_gain``, ``certified``, and
      ``region`` (0 plant unstable, 1 ring unstable, 2 string unstable, 3 string stable);
      ``grid["x"]``, ``grid["y"]`` are the axes' values;
    * ``curves`` (with ``boundaries``): as :func:`boundary`.
    """
    fixed, axes = _axes(parameters, x, True)
    (xn, xt), (yn, yt) = _axis_text(axes[0], 0), _axis_text(axes[1], 0)
    envelope, grid, curves = _ddemap.sweep(model, fixed, xn, xt, yn, yt, _ring(ring), bool(boundaries), str(ring_curves))
    r = _result(envelope)
    r["grid"] = grid
    r["x"]["values"] = grid["x"]
    r["y"]["values"] = grid["y"]
    if curves is not None:
        r["curves"] = curves
    return r


def boundary(model="ovrv", ring=22, seed_grid=41, ring_curves="auto", **parameters):
    """Stability boundaries in a window of two parameters, by continuation (``ddemap boundary``).

    Give exactly two parameters as ``(LO, HI)`` (the window) and the others as numbers. A
    ``seed_grid`` x ``seed_grid`` sweep seeds Newton-corrected points on the boundaries:
    Hopf curves ``f(i w; p1, p2) = 0`` of the plant and of every ring mode, the low-frequency
    curve ``c2(p1, p2) = 0`` and the peak curve ``|Gamma(iw)|^2 = 1, d/dw |Gamma|^2 = 0``; each
    branch is continued both ways by pseudo-arclength continuation and cut at the window edges.
    ``ring_curves``: which ring Hopf curves, as in :func:`sweep`.

    Returns the command's JSON keys (``curves`` summary replaced, ``seeds``,
    ``rejected_seeds``, ``seconds``) with ``curves`` a list of dicts: ``branch``, ``kind``
    ("hopf" or "string"), ``subkind`` ("plant", "ring", "lowfreq", "peak"), ``mode`` (ring
    mode or None), ``points``, ``max_residual``, ``closed``, and the arrays ``x``, ``y`` (the
    two parameters) and ``omega`` [rad/s] (crossing or peak frequency; 0 on the
    low-frequency curve).
    """
    seed_grid = _integer("seed_grid", seed_grid, 5, 2001)
    fixed, axes = _axes(parameters, None, False)
    (xn, xt), (yn, yt) = _axis_text(axes[0], seed_grid), _axis_text(axes[1], seed_grid)
    envelope, curves = _ddemap.boundary(model, fixed, xn, xt, yn, yt, _ring(ring), seed_grid, str(ring_curves))
    r = _result(envelope)
    summary = r["curves"]
    for i, c in enumerate(curves):  # the JSON's per-curve summary, then the arrays
        c["points"] = int(summary["points"][i])
    r["curves"] = curves
    return r


def classify(vehicles=None, ring=22, samples=4000, ring_samples=200, seed=1):
    """Plant, ring and string verdicts of calibrated OVRV vehicles (``ddemap classify``).

    ``vehicles``: None (the paper's calibration table, 14 settings), a CSV file
    ``name,k1,k2,th,tau[,eta]`` (k1 [1/s^2], k2 [1/s], th [s], tau [s], eta [m]; what
    ``calibrate`` writes), or built-in names such as ``"A_min,E_max"``. With the covariance
    columns of ``calibrate`` the verdicts come with probabilities from ``samples`` parameter
    draws (seed ``seed``; the first ``ring_samples`` also classified as rings). ``ring``: N or
    "inf" for the ring verdict.

    Returns ``vehicles`` (columns per vehicle: parameters, ``plant_stable``, ``ring_stable``,
    ``string_stable``, ``sup_gamma``, ``omega_peak``, ``lowfreq_margin``,
    ``spectral_abscissa``, ...) and the other keys of the command's JSON.
    """
    samples = _integer("samples", samples, 1, 1000000)
    ring_samples = _integer("ring_samples", ring_samples, 0, 1000000)
    seed = _integer("seed", seed, 0, 4294967295)
    if vehicles is not None and not isinstance(vehicles, str):
        vehicles = str(vehicles)  # a path-like
    if vehicles == "":
        raise ValueError("vehicles = '': expected a CSV file, built-in names or None (the paper's table)")
    return _result(_ddemap.classify(vehicles or "", _ring(ring), samples, ring_samples, seed))


def simulate(fleet, lead_profile=None, lead=None, on_event="continue", t_end=0.0, step=0.05, output_dt=0.1):
    """A platoon of OVRV cars behind a lead speed profile, nonlinear model (``ddemap simulate``).

    ``fleet``: followers in platoon order, built-in names with repeats (``"A_min*7,C_max"``) or
    a CSV file (a vehicle table as ``calibrate`` writes). ``lead_profile``: "dip" (default),
    "oscillatory", "step-low", "step-high"; or ``lead``: a CSV file ``time_s,lead_speed_mps``.
    ``on_event``: "stop" or "continue" at the first ACC disengagement or collision. ``t_end``
    [s] (0: the profile's last breakpoint + 30 s), ``step`` [s] (largest integration step),
    ``output_dt`` [s] (output sampling).

    Returns the command's JSON keys (``cars``: per follower ``lowest_speed``, ``speed_drop``
    [m/s], ``min_gap`` [m], ``events``; ``t_end``, ``steps``, ...) and ``series``: ``time``
    [s] and arrays of shape (cars + 1, samples), row 0 the lead: ``position`` [m], ``speed``
    [m/s], ``gap`` [m] (row 0 NaN).
    """
    if not isinstance(fleet, str) or not fleet:
        raise ValueError("fleet = %r: expected built-in names (e.g. 'A_min*7') or a CSV file" % (fleet,))
    envelope, series = _ddemap.simulate(fleet, lead_profile or "", str(lead) if lead else "", on_event,
                                        _number("t_end", t_end), _number("step", step), _number("output_dt", output_dt))
    r = _result(envelope)
    r["series"] = series
    return r


def calibrate(*files, joint=False, car="joint", train=None, bounds=None, gap_weight=0.02, model="ovrv", runs=None, data_dir=None,
              report=None):
    """Fits OVRV to measured car-following traces (``ddemap calibrate``).

    ``files``: CSV traces with columns time_s, lead_speed_mps, follower_speed_mps, gap_m (one
    fit per file, or one fit of all of them with ``joint=True``, named ``car``). ``train``:
    ``(T0, T1)`` [s], the training window (default the whole file). ``bounds``: a dict
    ``{"eta": (5, 15), ...}`` (default the paper's k1 0:1, k2 0:1, th 0:3, tau 0:1, eta 5:15).
    The fit minimises ``MSE(speed) + gap_weight * MSE(gap)`` [gap_weight in 1/s^2] over the
    simulated follower (RK4 with the delay).

    ``runs`` (instead of ``files``): a run list, CSV with columns car, file, role[, type]: each
    car fitted jointly on its ``role=train`` files and tested on its ``role=test`` files (errors
    per type); its file names are relative to ``data_dir`` (default the current folder).
    ``report``: a folder (created as needed) that receives table.csv, table.json, table.md and
    one fit figure per run, fit_CAR_FILE.svg, as ``--report`` writes them.

    Returns ``fits`` (per fit the parameters, errors, estimates with 95 % intervals, status,
    and with ``runs`` the test runs), ``gap_weight`` and ``bounds``, as the command's JSON.
    Ctrl-C stops it between fits.
    """
    if model != "ovrv":
        raise ValueError("model = %r: calibration supports ovrv" % (model,))
    if len(files) == 1 and isinstance(files[0], (list, tuple)):
        files = tuple(files[0])
    files = [str(f) for f in files]
    if not files and runs is None:
        raise ValueError("files: expected at least one trace (or runs=RUNS.csv)")
    if train is not None:
        if len(train) != 2:
            raise ValueError("train = %r: expected (T0, T1) in seconds" % (train,))
        train = (_number("train", train[0]), _number("train", train[1]))
    items = []
    for name, b in (bounds or {}).items():
        if len(b) != 2:
            raise ValueError("bounds[%r] = %r: expected (LO, HI)" % (name, b))
        if name not in ("k1", "k2", "th", "tau", "eta"):
            raise ValueError("bounds item %r: expected one of k1, k2, th, tau, eta" % (name,))
        items.append((name, _number("bounds " + name, b[0]), _number("bounds " + name, b[1])))
    if report is not None:
        report = str(report)
        if _os.path.exists(report) and not _os.path.isdir(report):
            raise ValueError("report = %r: expected a folder" % (report,))
        _os.makedirs(report, exist_ok=True)
    return _result(_ddemap.calibrate(files, bool(joint), car, train, items, _number("gap_weight", gap_weight),
                                     "" if runs is None else str(runs), "" if data_dir is None else str(data_dir),
                                     "" if report is None else report))


def mixed_ring(fleet, ring=None, speed=None, length=None, solver="auto", count=6, degree=0):
    """Rightmost roots of a ring of mixed cars (``ddemap roots --fleet``).

    ``fleet``: a CSV file (a fleet table, or a vehicle table as ``calibrate`` writes) or
    built-in names ``"A_min,C_max*3,E_min"``; ``ring``: the number of cars (the fleet repeated;
    default the fleet once). The equilibrium: a common ``speed`` [m/s] (default 20) or the
    ring ``length`` [m]. The roots of ``det Delta = prod P_i - prod Q_i`` (cars that react
    only to the car ahead), or of ``prod P_i det(I - prod T_i)`` with 2 x 2 transfer matrices
    (connected cruise control cars, which also react to the car two ahead), are located and
    certified complete by the argument principle (``solver="product"``, the default through
    ``"auto"``); or collocation, ``"dense"`` or ``"sparse"`` (shift-invert Arnoldi), with
    ``degree`` M (0: automatic).

    Returns ``roots`` (columns ``re``, ``im``, ``residual``, ...), ``spectral_abscissa``,
    ``ring_stable``, ``unstable_roots``, the equilibrium and the other keys of the command's
    JSON; ``solver`` (given, used) is an attribute.
    """
    if not isinstance(fleet, str) or not fleet:
        raise ValueError("fleet = %r: expected a CSV file or built-in names such as 'A_min,C_max*3'" % (fleet,))
    if speed is not None and length is not None:
        raise ValueError("speed and length: expected only one of them")
    count = _integer("count", count, 1, 10000)
    degree = _integer("degree", degree, 0, 200)
    if degree == 1:
        raise ValueError("degree = 1: expected 0 (automatic) or an integer 2..200")
    return _result(_ddemap.mixed_ring(fleet, False, 0 if ring is None else _ring(ring, allow_inf=False),
                                      None if speed is None else _number("speed", speed),
                                      None if length is None else _number("length", length), solver, count, degree))


def _nonlinear_problem(system, model, ring, parameters):
    """The problem arguments of equilibria, hopf and orbits, checked as the commands check them."""
    if (system is None) == (model is None):
        raise ValueError("expected one of system=FILE or model='ov'|'idm' (with ring=N)")
    if system is not None:
        if ring is not None or parameters:
            raise ValueError("system takes the whole problem from the file: expected no ring or model parameters")
        return str(system), "", 0, {}
    if ring is None:
        raise ValueError("model=" + repr(model) + " needs ring=N: expected the number of cars")
    return "", str(model), _integer("ring", ring, 2, 2000), _parameters(parameters)


def equilibria(par, from_, to, system=None, model=None, ring=None, count=4, max_points=400, **parameters):
    """A branch of equilibria of a nonlinear DDE in one parameter (``ddemap equilibria``).

    ``system``: a JSON file (variables, parameters, equations, equilibrium guess), or ``model``
    with ``ring`` N: ``"ov"``, the optimal-velocity ring with reaction delay (``alpha`` [1/s],
    ``tau`` [s], ``v0`` [m/s], ``h_st`` [m], ``headway`` [m]), or ``"idm"``, the intelligent
    driver model ring with sensing delay (``a``, ``b`` [m/s^2], ``v0`` [m/s], ``delta``, ``th``
    [s], ``eta`` [m], ``tau`` [s], ``gap`` [m]; ``th`` and ``tau`` required). The branch in the
    parameter ``par`` starts at ``from_`` (``--from``) and is followed by pseudo-arclength
    continuation (through folds) until the parameter leaves [from_, to] or ``max_points``;
    at every point the ``count`` rightmost roots of the linearisation decide stability; folds
    and Hopf points (a pair crossing the imaginary axis) are located by Newton.

    Returns ``points`` (columns ``par``, ``x``, ``abscissa``, ``unstable``, ``stable``, ...),
    ``folds``, ``hopf`` (``par``, ``omega`` [rad/s], ...), ``stop``: the command's JSON.
    """
    sys_, model_, n, p = _nonlinear_problem(system, model, ring, parameters)
    count = _integer("count", count, 1, 100)
    max_points = _integer("max_points", max_points, 2, 100000)
    return _result(_ddemap.equilibria(sys_, model_, n, p, par, _number("from_", from_), _number("to", to), count, max_points))


def hopf(par, from_, to, system=None, model=None, ring=None, par2=None, from2=None, to2=None, max_points=400, **parameters):
    """Hopf points on the equilibrium branch with their criticality (``ddemap hopf``).

    The problem as in :func:`equilibria`; ``from_ < to``. Every Hopf point gets the first
    Lyapunov coefficient ``l1`` (DDE-BIFTOOL's normalisation: ||q|| = 1, p Delta'(i omega) q = 1,
    L1 = Re c1 / omega), its ``criticality`` (subcritical L1 > 0, supercritical L1 < 0),
    ``dre_dpar`` (d Re lambda / d par) and ``amplitude_coefficient`` (max - min of each variable
    of the bifurcating orbit per sqrt|par - par_H|). With ``par2``, ``from2``, ``to2``: the Hopf
    curves in (par, par2) through those points and the generalised Hopf points (L1 = 0) on them.
    Returns the command's JSON as Python objects.
    """
    sys_, model_, n, p = _nonlinear_problem(system, model, ring, parameters)
    max_points = _integer("max_points", max_points, 2, 100000)
    return _result(_ddemap.hopf(sys_, model_, n, p, par, _number("from_", from_), _number("to", to), par2 or "",
                                None if from2 is None else _number("from2", from2), None if to2 is None else _number("to2", to2),
                                max_points))


def orbits(par, from_, to, system=None, model=None, ring=None, hopf=0, degree=4, intervals=40, points=100, adapt=False,
           max_step=None, **parameters):
    """The branch of periodic orbits born at a Hopf point (``ddemap orbits``).

    The problem as in :func:`equilibria`; the equilibrium branch from ``from_`` to ``to`` gives
    the Hopf points, number ``hopf`` (from 0) starts the orbits: piecewise polynomials of degree
    ``degree`` on ``intervals`` mesh intervals, the period an unknown, at most ``points`` orbits.
    ``max_step`` (the command's ``--max-step``; default 0.1 when None): the largest step along
    the branch in its weighted norm, from 0.02 (the first step) to 1e6; a larger one covers the
    same stretch of the branch with fewer orbits (README, orbits).
    Returns ``points`` (``par``, ``period`` [time units of the system], ``min``, ``max`` per
    variable, ``stable``, ``multipliers``: Floquet multipliers as [re, im]), ``folds``,
    ``period_doublings``, ``tori``: the command's JSON.
    """
    sys_, model_, n, p = _nonlinear_problem(system, model, ring, parameters)
    step = None if max_step is None else _number("max_step", max_step)
    return _result(_ddemap.orbits(sys_, model_, n, p, par, _number("from_", from_), _number("to", to),
                                  _integer("hopf", hopf, 0, 1000000), _integer("degree", degree, 1, 20),
                                  _integer("intervals", intervals, 2, 10000), _integer("points", points, 2, 100000), bool(adapt),
                                  step))