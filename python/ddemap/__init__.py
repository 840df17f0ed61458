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
import functools as _functools
import os as _os
import sys as _sys
import time as _time
import warnings as _warnings

import numpy as _np

from . import _ddemap

__all__ = ["__version__", "Result", "CalibrationWarning", "roots", "string", "sweep", "boundary", "classify", "simulate", "calibrate",
           "mixed_ring", "mix", "growth", "design", "chart", "paper", "atlas", "equilibria", "hopf", "orbits", "bistability", "version"]

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

    _envelope = None  # the command's JSON envelope, as the library wrote it

    @property
    def converged(self):
        """True when ``status`` is ``"converged"``."""
        return self.status == "converged"

    def to_dict(self):
        """The command's JSON envelope as plain Python (``command``, ``version``, ``inputs``,
        ``solver``, ``status``, ``message``, ``result``): what ``ddemap COMMAND --format json``
        prints, numbers exact. Arrays the wrapper added (e.g. ``series`` of :func:`simulate`)
        are lists under ``extra``."""
        e = _json.loads(self._envelope) if self._envelope else {
            "command": self.command, "version": self.version, "inputs": self.inputs, "solver": self.solver,
            "status": self.status, "message": self.message, "result": {}}
        extra = {k: _plain(v) for k, v in self.items() if k not in e["result"]}
        if extra:
            e["extra"] = extra
        return e

    def to_json(self, **kwargs):
        """:meth:`to_dict` as JSON text (``json.dumps`` keyword arguments pass through);
        :func:`Result.from_json` reads it back."""
        return _json.dumps(self.to_dict(), allow_nan=False, **kwargs)

    @staticmethod
    def from_json(text):
        """The Result of :meth:`to_json` text (or of ``ddemap COMMAND --format json`` output)."""
        e = _json.loads(text)
        extra = e.pop("extra", {})
        r = _result(_json.dumps(e))
        for k, v in extra.items():
            r[k] = _restore(v)
        return r

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


def _restore(value):
    """The arrays the wrapper added (:meth:`Result.to_dict`'s ``extra``) back as NumPy: a list of
    equal-length lists of numbers as a 2-D array (e.g. ``series["speed"]``, cars x samples), a
    list of numbers as a 1-D array, dicts entry by entry."""
    if isinstance(value, dict):
        return {k: _restore(v) for k, v in value.items()}
    if isinstance(value, list) and value and all(isinstance(v, list) for v in value):
        # nested lists level by level (an atlas field has one level per grid dimension); a row of
        # nulls (e.g. the lead's gap) is a row of NaN
        rows = [_np.full(len(v), _math.nan) if v and all(x is None for x in v) else _restore(v) for v in value]
        if all(isinstance(x, _np.ndarray) for x in rows) and len({(x.shape, x.dtype) for x in rows}) == 1:
            return _np.array(rows)
        return rows
    return _convert(value)


def _plain(v):
    """NumPy values -> JSON-ready Python (NaN -> None)."""
    if isinstance(v, dict):
        return {k: _plain(x) for k, x in v.items()}
    if isinstance(v, _np.ndarray):
        return _plain(v.tolist())
    if isinstance(v, (list, tuple)):
        return [_plain(x) for x in v]
    if isinstance(v, (_np.floating, float)):
        return None if not _math.isfinite(float(v)) else float(v)
    if isinstance(v, _np.integer):
        return int(v)
    if isinstance(v, _np.bool_):
        return bool(v)
    return v


def _result(envelope_text):
    e = _json.loads(envelope_text)
    r = Result(_convert(e["result"]))
    r._envelope = envelope_text
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
    if isinstance(ring, str) and ring.strip().lower() in ("inf", "infinity") and allow_inf:
        return 0
    if isinstance(ring, bool) or not isinstance(ring, (int, _np.integer)) or not 2 <= ring <= 1000000000:
        expected = "an integer N >= 2 (at most 10^9)" + (" or 'inf'" if allow_inf else "; this ring is finite")
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
        if counts and _is_grid(v):
            v = _grid_axis(name, v)
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


def _is_grid(v):
    """An axis given as its values (a NumPy array, or a list or tuple that is not (LO, HI, COUNT))."""
    if isinstance(v, _np.ndarray):
        return True
    if isinstance(v, (list, tuple)):
        triple = len(v) == 3 and isinstance(v[2], (int, _np.integer)) and not isinstance(v[2], bool)
        return not triple and len(v) >= 2
    return False


def _grid_axis(name, values):
    """Evenly spaced values (np.linspace(lo, hi, count)) -> (lo, hi, count); anything else is an error."""
    try:
        a = _np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise TypeError("%s: expected numbers (an array such as np.linspace(lo, hi, count), or (LO, HI, COUNT))" % (name,)) from None
    if a.ndim != 1 or a.size < 2 or not _np.all(_np.isfinite(a)):
        raise ValueError("%s: expected a one-dimensional array of at least 2 finite values" % (name,))
    step = (a[-1] - a[0]) / (a.size - 1)
    if not step > 0 or _np.max(_np.abs(_np.diff(a) - step)) > 1e-9 * (abs(a[-1]) + abs(a[0]) + step):
        raise ValueError("%s: the %d values are not increasing evenly (the chart's grid is LO..HI in equal steps): "
                         "expected np.linspace(lo, hi, count) or (LO, HI, COUNT)" % (name, a.size))
    return (float(a[0]), float(a[-1]), int(a.size))


def _text(v):
    """A number as the shortest text that reads back to it (1.0 as "1", as typed on a command line)."""
    t = repr(float(v))
    return t[:-2] if t.endswith(".0") else t


def _axis_text(axis, grid):
    name, lo, hi, count = axis
    return name, "%s:%s:%d" % (_text(lo), _text(hi), count if count is not None else grid)


_TYPES_TABLE = "a pandas DataFrame, a dict of columns, a list of row dicts"


def _is_frame(v):
    return hasattr(v, "columns") and hasattr(v, "to_dict") and hasattr(v, "__getitem__")


def _field(v):
    """One CSV field: numbers in the shortest form that reads back exactly, NaN/None empty."""
    if v is None:
        return ""
    if isinstance(v, (bool, _np.bool_)):
        return "true" if v else "false"
    if isinstance(v, (int, _np.integer)):
        return str(int(v))
    if isinstance(v, (float, _np.floating)):
        f = float(v)
        if _math.isnan(f):
            return ""
        return repr(f) if _math.isfinite(f) else ("inf" if f > 0 else "-inf")
    t = str(v)
    if any(c in t for c in ',"\n\r'):
        t = '"' + t.replace('"', '""') + '"'
    return t


def _table_text(value, what):
    """A table in memory (DataFrame, dict of columns or of one row's values, list of row dicts)
    as CSV text, or None when `value` is none of these."""
    if _is_frame(value):
        columns = [str(c) for c in value.columns]
        data = [list(value[c]) for c in value.columns]
    elif isinstance(value, dict):
        if not value:
            raise ValueError("%s: an empty dict: expected columns (name -> values)" % (what,))
        columns = [str(c) for c in value]
        vals = list(value.values())
        if all(isinstance(v, (str, int, float, bool, _np.generic)) or v is None for v in vals):
            data = [[v] for v in vals]  # one row
        else:
            data = []
            for c, v in zip(columns, vals):
                if isinstance(v, (str, bytes)) or not hasattr(v, "__len__"):
                    raise ValueError("%s: column %r is %r: expected a sequence of values like the other columns" % (what, c, v))
                data.append(list(v))
            lengths = {len(d) for d in data}
            if len(lengths) != 1:
                raise ValueError("%s: columns of different lengths %s: expected equal lengths" % (what, sorted(lengths)))
    elif isinstance(value, (list, tuple)) and value and all(isinstance(r, dict) for r in value):
        columns = []
        for r in value:
            columns += [str(k) for k in r if str(k) not in columns]
        data = [[r.get(c) for r in value] for c in columns]
    else:
        return None
    rows = len(data[0]) if data else 0
    lines = [",".join(_field(c) for c in columns)]
    lines += [",".join(_field(col[i]) for col in data) for i in range(rows)]
    return "\n".join(lines) + "\n"


def _cars(value, what, tables=None):
    """A car list from Python: (the list's text, {name: table text}). Takes the command line's car
    list syntax (str), a path (os.PathLike), a table in memory, a Result of calibrate, or a list or
    tuple of these (joined in order)."""
    tables = {} if tables is None else tables
    if isinstance(value, str):
        if not value.strip():
            raise ValueError("%s = %r: expected cars (e.g. 'A_min*7', 'mycars.csv', 'ovrv:k1=0.1,k2=0.4,th=1.5,tau=0.5')" % (what, value))
        return value, tables
    if isinstance(value, _os.PathLike):
        return _os.fspath(value), tables
    if isinstance(value, Result):
        if value.command != "calibrate" or not value._envelope:
            raise ValueError("%s: a Result of %r: expected the Result of calibrate (its fits are cars)" % (what, value.command))
        name = "<calibrate result %d>" % (len(tables) + 1)
        tables[name] = value._envelope
        return name, tables
    text = _table_text(value, what)
    if text is not None:
        kind = "DataFrame" if _is_frame(value) else "dict" if isinstance(value, dict) else "rows"
        name = "<%s %d>" % (kind, len(tables) + 1)
        tables[name] = text
        return name, tables
    if isinstance(value, (list, tuple)) and value:
        items = []
        for v in value:
            item, tables = _cars(v, what, tables)
            items.append(item)
        return ",".join(items), tables
    raise TypeError("%s: %s: expected a car list string ('A_min*7,mycars.csv:Sedan'), an os.PathLike, %s, "
                    "the Result of calibrate, or a list of these" % (what, type(value).__name__, _TYPES_TABLE))


def _traces(values):
    """The traces of calibrate: [(source, text)], text empty for a file."""
    out = []
    for v in values:
        if isinstance(v, (str, _os.PathLike)):
            out.append((_os.fspath(v), ""))
        elif isinstance(v, Result) and v.command == "simulate":
            out.append(("simulate%d" % (len(out) + 1), _platoon_text(v)))
        else:
            text = _table_text(v, "trace %d" % (len(out) + 1))
            if text is None:
                raise TypeError("trace %d: %s: expected a CSV path (str or os.PathLike), %s with columns time_s, "
                                "lead_speed_mps, follower_speed_mps, gap_m, or the Result of simulate"
                                % (len(out) + 1, type(v).__name__, _TYPES_TABLE))
            kind = "DataFrame" if _is_frame(v) else "dict" if isinstance(v, dict) else "rows"
            out.append(("trace%d" % (len(out) + 1), text))
    return out


def _platoon_text(r):
    """simulate's CSV (time_s, car, position_m, speed_mps, gap_m) from its Result's series."""
    s = r["series"]
    t, x, v, g = s["time"], s["position"], s["speed"], s["gap"]
    lines = ["time_s,car,position_m,speed_mps,gap_m"]
    for k in range(len(t)):
        for c in range(v.shape[0]):
            lines.append("%s,%d,%s,%s,%s" % (_field(t[k]), c, _field(x[c, k]), _field(v[c, k]), "" if c == 0 else _field(g[c, k])))
    return "\n".join(lines) + "\n"


def _lead(lead):
    """simulate's lead: (file, text, car): a path (P.csv:K for car K of simulate's CSV), a table in
    memory (time_s, lead_speed_mps), a (t, v) pair of arrays, or (Result of simulate, K)."""
    if lead is None:
        return "", "", -1
    if isinstance(lead, (str, _os.PathLike)):
        path = _os.fspath(lead)
        head, _, tail = path.rpartition(":")
        if not _os.path.exists(path) and head and tail.isdigit():
            return head, "", int(tail)
        return path, "", -1
    if isinstance(lead, Result):
        raise TypeError("lead: a Result of %r alone: expected (Result of simulate, K), K the car whose speed leads (0 = its lead)" % (lead.command,))
    if isinstance(lead, tuple) and len(lead) == 2 and isinstance(lead[0], Result):
        if lead[0].command != "simulate":
            raise ValueError("lead = (Result of %r, K): expected the Result of simulate" % (lead[0].command,))
        return "<simulate result>", _platoon_text(lead[0]), _integer("lead car", lead[1], 0, 1000000)
    if isinstance(lead, tuple) and len(lead) == 2 and not isinstance(lead[0], dict):
        t, v = (_np.asarray(a, dtype=float) for a in lead)
        if t.ndim != 1 or t.shape != v.shape:
            raise ValueError("lead = (t, v): expected two one-dimensional arrays of the same length, got shapes %s and %s" % (t.shape, v.shape))
        return "<(t, v)>", _table_text({"time_s": t, "lead_speed_mps": v}, "lead"), -1
    text = _table_text(lead, "lead")
    if text is None:
        raise TypeError("lead: %s: expected a CSV path (str or os.PathLike, P.csv:K for car K of simulate's CSV), %s with "
                        "columns time_s, lead_speed_mps, a (t, v) pair of arrays, or (Result of simulate, K)" % (type(lead).__name__, _TYPES_TABLE))
    kind = "DataFrame" if _is_frame(lead) else "dict" if isinstance(lead, dict) else "rows"
    return "<%s>" % kind, text, -1


class _StderrProgress:
    """The default progress: silent for the first second, then one line on stderr, rewritten in
    place on a terminal, a new line at most every 5 s otherwise (as the command line)."""

    def __init__(self, command):
        self.command = command
        self.start = _time.monotonic()
        self.last = 0.0
        self.shown = False
        self.tty = _sys.stderr.isatty()

    def __call__(self, done, total):
        now = _time.monotonic()
        if now - self.start < 1.0 or (not self.tty and now - self.last < 5.0):
            return
        self.last = now
        line = "ddemap: %s: %d/%d (%.0f s)" % (self.command, done, total, now - self.start)
        _sys.stderr.write(("\r" + line + "   ") if self.tty else line + "\n")
        _sys.stderr.flush()
        self.shown = True

    def close(self):
        if self.shown and self.tty:
            _sys.stderr.write("\n")


def _with_progress(f):
    """Adds ``progress=``: None (the default: a line on stderr for calls over a second), False
    (none) or a callable ``progress(done, total)`` called at most 5 times a second on the calling
    thread; an exception it raises stops the call and is raised from it."""
    command = f.__name__

    @_functools.wraps(f)
    def call(*args, progress=None, **kwargs):
        if progress is None:
            callback = _StderrProgress(command)
        elif progress is False:
            callback = None
        elif callable(progress):
            callback = progress
        else:
            raise TypeError("progress = %r: expected None, False or a callable progress(done, total)" % (progress,))
        _ddemap.set_progress(callback)
        try:
            return f(*args, **kwargs)
        finally:
            _ddemap.set_progress(None)
            if isinstance(callback, _StderrProgress):
                callback.close()

    call.__doc__ = (f.__doc__ or "") + "\n    ``progress``: None (a line on stderr for calls over a second), False, or a callable ``progress(done, total)``.\n"
    return call


# ------------------------------------------------------------------ commands


@_with_progress
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


@_with_progress
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
    ``string_stable``, ``peaks``; the peak (L-infinity) notion, ||h||_1 <= 1 for the impulse
    response h of Gamma (the follower's speed never overshoots the car ahead's):
    ``peak_stable`` (None when undecided), ``peak_verdict``, ``peak_norm`` (||h||_1; None when
    infinite or undecided), ``peak_norm_error``, ``peak_overshoot`` (of a unit step);
    with ``ring`` also ``ring_stable``, ``spectral_abscissa``, ``ring_margin``.
    """
    return _result(_ddemap.string(model, _parameters(parameters), None if ring is None else _ring(ring)))


@_with_progress
def sweep(model="ovrv", ring=22, x=None, boundaries=True, ring_curves="auto", mark=None, out=None, peak=False, **parameters):
    """A stability chart over two model parameters (``ddemap sweep``).

    Give exactly two parameters as ``(LO, HI, COUNT)`` (the axes, COUNT >= 2 grid points from
    LO to HI inclusive) and the others as numbers, e.g.
    ``sweep(th=1.5, tau=0.1, k1=(0.01, 1, 200), k2=(0.01, 1, 200))``. ``x`` names the horizontal
    axis (default: the alphabetically first). At each grid point the rightmost root of every
    ring mode and of the plant is continued along the rows and certified by the argument
    principle; the string-stability quantities are those of :func:`string`. ``boundaries``:
    also trace the stability boundaries by continuation; ``peak=True``: also decide peak
    (L-infinity) string stability at every L2-stable point (grid keys ``peak_norm``, NaN where not
    computed, and ``peak_stable``; as ``--peak``); ``ring_curves``: "all" (every ring
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

    ``mark``: cars drawn on the chart (as ``--mark``: any car list, a DataFrame or dict of a car
    table, a Result of :func:`calibrate`, ...), each at its values of the two swept parameters,
    with its 95 % confidence ellipse where it has a fit's covariance; ``out``: PREFIX of the
    command's files (PREFIX.csv, .json, .svg, -boundaries.csv; folders created as needed). A
    marked car whose other parameters differ from the chart's is named in a ``UserWarning``.
    """
    fixed, axes = _axes(parameters, x, True)
    (xn, xt), (yn, yt) = _axis_text(axes[0], 0), _axis_text(axes[1], 0)
    spec, tables = ("", {}) if mark is None else _cars(mark, "mark")
    prefix = "" if out is None else _prefix(out, "sweep", (".csv", ".json", ".svg", "-boundaries.csv"))
    envelope, grid, curves = _ddemap.sweep(model, fixed, xn, xt, yn, yt, _ring(ring), bool(boundaries), str(ring_curves), spec, tables, prefix,
                                           bool(peak))
    r = _result(envelope)
    r["grid"] = grid
    r["x"]["values"] = grid["x"]
    r["y"]["values"] = grid["y"]
    if curves is not None:
        r["curves"] = curves
    return r


@_with_progress
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


@_with_progress
def classify(vehicles=None, ring=22, samples=4000, ring_samples=200, seed=1, peak=True, distance=False):
    """Plant, ring and string verdicts of calibrated OVRV vehicles (``ddemap classify``).

    ``vehicles``: None (the paper's calibration table, 14 settings) or cars, as everywhere: a car
    list in the command line's syntax (``"A_min,E_max"``, ``"mycars.csv"``, ``"mycars.csv:Sedan"``,
    ``"ovrv:k1=0.1,k2=0.4,th=1.5,tau=0.5"``, each with ``*K``), an ``os.PathLike``, a pandas
    DataFrame, a dict of columns or a list of row dicts (columns ``name, k1, k2, th, tau[, eta]``
    as in a car table: k1 [1/s^2], k2 [1/s], th [s], tau [s], eta [m]), the Result of
    :func:`calibrate`, or a list of these. Each distinct car is classified once. With the
    covariance of a fit the verdicts come with probabilities from ``samples`` parameter draws
    (seed ``seed``; the first ``ring_samples`` also classified as rings). ``ring``: N or "inf".
    ``peak`` (default True; False skips it, ``--no-peak``) decides peak (L-infinity) string
    stability too (``peak_verdict``, ``peak_stable``, ``peak_norm`` = ||h||_1, ``peak_norm_error``,
    ``peak_overshoot`` per vehicle; see :func:`string`). ``distance=True`` also finds the distance to the other string verdict
    (``verdict_distance`` per vehicle: the smallest relative change of (k1, k2, th, tau),
    sqrt(sum ((x - x0) / x0)^2), found to turn a string-stable car unstable or an unstable one
    stable, the parameters ``at`` the flip and the ``boundary`` reached; ``ddemap classify --distance``).

    Returns ``vehicles`` (columns per vehicle: parameters, ``plant_stable``, ``ring_stable``,
    ``string_stable``, ``sup_gamma``, ``omega_peak``, ``lowfreq_margin``,
    ``spectral_abscissa``, ...) and the other keys of the command's JSON.
    """
    samples = _integer("samples", samples, 1, 1000000)
    ring_samples = _integer("ring_samples", ring_samples, 0, 1000000)
    seed = _integer("seed", seed, 0, 4294967295)
    spec, tables = ("", {}) if vehicles is None else _cars(vehicles, "vehicles")
    if not isinstance(peak, bool):
        raise ValueError(f"peak = {peak!r}: expected True or False")
    if not isinstance(distance, bool):
        raise ValueError(f"distance = {distance!r}: expected True or False")
    return _result(_ddemap.classify(spec, tables, _ring(ring), samples, ring_samples, seed, peak, distance))


@_with_progress
def simulate(fleet, lead_profile=None, lead=None, on_event="continue", t_end=0.0, step=0.05, output_dt=0.1, noise=None, seed=1):
    """A platoon of OVRV cars behind a lead speed profile, nonlinear model (``ddemap simulate``).

    ``fleet``: the followers in platoon order, cars as :func:`classify` takes them (a car list
    such as ``"A_min*7,C_max"``, a path, a DataFrame, dict or rows, a calibrate Result, or a list
    of these). ``lead_profile``: "dip" (default), "oscillatory", "step-low", "step-high"; or
    ``lead``: a CSV path with columns ``time_s,lead_speed_mps`` (``"P.csv:K"``: car K of the CSV
    that simulate writes), a DataFrame or dict with those columns, a ``(t, v)`` pair of arrays
    [s, m/s], or ``(result_of_simulate, K)``. ``on_event``: "stop" or "continue" (default) at
    the first ACC disengagement or collision. ``t_end`` [s] (0: the profile's last breakpoint
    + 30 s), ``step`` [s] (largest integration step), ``output_dt`` [s] (output sampling).
    ``noise``: ``(sd_speed, sd_gap)`` [m/s, m], Gaussian measurement noise added to the series
    (not to the dynamics or the summary), drawn with ``seed``.

    Returns the command's JSON keys (``cars``: per follower ``lowest_speed``, ``speed_drop``
    [m/s], ``min_gap`` [m], ``events``; ``t_end``, ``steps``, ...) and ``series``: ``time``
    [s] and arrays of shape (cars + 1, samples), row 0 the lead: ``position`` [m], ``speed``
    [m/s], ``gap`` [m] (row 0 NaN). The Result can be passed to :func:`calibrate`.
    """
    spec, tables = _cars(fleet, "fleet")
    lead_file, lead_text, lead_car = _lead(lead)
    sd_speed, sd_gap = 0.0, 0.0
    if noise is not None:
        if not isinstance(noise, (tuple, list)) or len(noise) != 2:
            raise ValueError("noise = %r: expected (sd_speed, sd_gap) in m/s and m" % (noise,))
        sd_speed, sd_gap = _number("noise sd_speed", noise[0]), _number("noise sd_gap", noise[1])
    envelope, series = _ddemap.simulate(spec, tables, lead_profile or "", lead_file, lead_text, lead_car, on_event,
                                        _number("t_end", t_end), _number("step", step), _number("output_dt", output_dt),
                                        sd_speed, sd_gap, _integer("seed", seed, 0, 4294967295))
    r = _result(envelope)
    r["series"] = series
    return r


@_with_progress
def calibrate(*traces, joint=False, car="joint", train=None, bounds=None, gap_weight=0.02, lead_noise="auto", model="ovrv", runs=None,
              data_dir=None, report=None, follower=None, warn=True, lead_noise_correction=True):
    """Fits OVRV to measured car-following traces (``ddemap calibrate``).

    ``traces``: each a CSV path (str or ``os.PathLike``), a pandas DataFrame, dict of columns
    or list of row dicts with columns time_s, lead_speed_mps, follower_speed_mps, gap_m, or a
    platoon: the CSV that simulate writes or the Result of :func:`simulate` (every follower a
    trace, or only ``follower`` K). One fit per trace, or one fit of all of them with
    ``joint=True``, named ``car``. ``train``: ``(T0, T1)`` [s], the training window (default
    the whole file). ``bounds``: a dict ``{"eta": (5, 15), ...}`` (default the paper's k1 0:1,
    k2 0:1, th 0:3, tau 0:1, eta 5:15). The fit minimises ``MSE(speed) + gap_weight * MSE(gap)``
    [gap_weight in 1/s^2] over the simulated follower (RK4 with the delay). ``lead_noise``: the
    white noise on the measured lead speed [m/s] that the fit corrects its bias for and the
    intervals allow for (``"auto"``: estimated from each trace's lead speed; 0: the lead speed is
    exact), as ``--lead-noise``; ``lead_noise_correction=False`` fits plain least squares
    (``--lead-noise-correction off``).

    ``runs`` (instead of ``traces``): a run list, CSV with columns car, file, role[, type]: each
    car fitted jointly on its ``role=train`` files and tested on its ``role=test`` files (errors
    per type); its file names are relative to ``data_dir`` (default the current folder).
    ``report``: a folder (created as needed) that receives table.csv, table.json, table.md and
    one fit figure per run, fit_CAR_FILE.svg, as ``--report`` writes them.

    Returns ``fits`` (per fit the parameters, errors, estimates with 95 % intervals, status,
    warnings, and with ``runs`` the test runs), ``gap_weight`` and ``bounds``, as the command's
    JSON. Each fit's warnings are also issued with ``warnings.warn`` (``warn=False``: not).
    The Result is a car list for :func:`classify`, :func:`simulate`, :func:`growth`, ...
    Ctrl-C stops it within a fit.
    """
    files = traces
    if model != "ovrv":
        raise ValueError("model = %r: calibration supports ovrv" % (model,))
    if len(files) == 1 and isinstance(files[0], list):
        files = tuple(files[0])
    files = _traces(files)
    follower = 0 if follower is None else _integer("follower", follower, 1, 1000000)
    if not files and runs is None:
        raise ValueError("files: expected at least one trace (or runs=RUNS.csv)")
    if train is not None:
        if len(train) != 2:
            raise ValueError("train = %r: expected (T0, T1) in seconds" % (train,))
        train = (_number("train", train[0]), _number("train", train[1]))
    if isinstance(lead_noise, str) and lead_noise == "auto":
        lead_noise = -1.0
    else:
        lead_noise = _number("lead_noise", lead_noise)
        if not 0 <= lead_noise <= 10:
            raise ValueError("lead_noise = %r: expected 'auto', or 0 to 10 m/s (0: the lead speed is exact)" % (lead_noise,))
    items = []
    for name, b in (bounds or {}).items():
        if len(b) != 2:
            raise ValueError("bounds[%r] = %r: expected (LO, HI)" % (name, b))
        if name not in ("k1", "k2", "th", "tau", "eta"):
            raise ValueError("bounds item %r: expected one of k1, k2, th, tau, eta" % (name,))
        items.append((name, _number("bounds " + name, b[0]), _number("bounds " + name, b[1])))
    if report is not None:
        report = _os.fspath(report)
        if _os.path.exists(report) and not _os.path.isdir(report):
            raise ValueError("report = %r: expected a folder" % (report,))
        _os.makedirs(report, exist_ok=True)
    r = _result(_ddemap.calibrate(files, follower, bool(joint), car, train, items, _number("gap_weight", gap_weight), lead_noise,
                                  bool(lead_noise_correction),
                                  "" if runs is None else _os.fspath(runs), "" if data_dir is None else _os.fspath(data_dir),
                                  "" if report is None else report))
    if warn:
        for f in _json.loads(r._envelope)["result"].get("fits", []):
            for text in f.get("warnings", []):
                _warnings.warn("calibrate: %s: %s" % (f.get("name", "?"), text), CalibrationWarning, stacklevel=2)
    return r


class CalibrationWarning(UserWarning):
    """A fit's warning (a parameter the data hardly determine, a bound reached, ...)."""


@_with_progress
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
    fleet, tables = _cars(fleet, "fleet")
    if speed is not None and length is not None:
        raise ValueError("speed and length: expected only one of them")
    count = _integer("count", count, 1, 10000)
    degree = _integer("degree", degree, 0, 200)
    if degree == 1:
        raise ValueError("degree = 1: expected 0 (automatic) or an integer 2..200")
    return _result(_ddemap.mixed_ring(fleet, tables, False, 0 if ring is None else _ring(ring, allow_inf=False),
                                      None if speed is None else _number("speed", speed),
                                      None if length is None else _number("length", length), solver, count, degree))


@_with_progress
def mix(x, y, ring=40, p=(0, 1, 11), draws=0, seed=1, speed=None, length=None, solver="auto"):
    """Stability of a ring of two car types against the fraction p of type X (``ddemap mix``).

    ``x``, ``y``: one car each, given as :func:`classify` takes cars (``"A_min"``,
    ``"mycars.csv:Sedan"``, ``"ovrv:k1=..."``, a one-row DataFrame or dict, a calibrate Result
    of one fit). ``ring``: N >= 2 cars; ``p``: the fractions, ``(LO, HI, COUNT)`` in [0, 1] or an
    array of values; ``draws`` random arrangements per p besides the evenly spread one (seed
    ``seed``); the equilibrium at a common ``speed`` [m/s] (default 20) or ring ``length`` [m];
    ``solver`` as :func:`mixed_ring`.

    Returns ``points`` (per fraction ``p``, ``x_cars``, ``abscissa`` [1/s], its range over the
    arrangements, ``stable``, ...) and the other keys of the command's JSON.
    """
    tables = {}
    xs, tables = _cars(x, "x", tables)
    ys, tables = _cars(y, "y", tables)
    if isinstance(p, tuple) and len(p) == 3 and isinstance(p[2], (int, _np.integer)) and not isinstance(p[2], bool):
        lo, hi, count = _number("p", p[0]), _number("p", p[1]), _integer("p count", p[2], 1, 100000)
        fractions = [lo] if count == 1 else [lo + (hi - lo) * i / (count - 1) for i in range(count)]
    else:
        fractions = [_number("p", v) for v in _np.atleast_1d(_np.asarray(p, dtype=float)).tolist()]
    if not fractions or any(not 0 <= f <= 1 for f in fractions):
        raise ValueError("p = %r: expected fractions in [0, 1]" % (p,))
    if speed is not None and length is not None:
        raise ValueError("speed and length: expected only one of them")
    return _result(_ddemap.mix(xs, ys, tables, _ring(ring, allow_inf=False), fractions, _integer("draws", draws, 0, 10000),
                               _integer("seed", seed, 0, 4294967295), None if speed is None else _number("speed", speed),
                               None if length is None else _number("length", length), str(solver)))


@_with_progress
def growth(vehicles=None, followers=15, lead_profile=None, lead=None):
    """Disturbance growth along platoons of each car (``ddemap growth``): every distinct car of
    ``vehicles`` (None: the paper's table; otherwise cars as :func:`classify` takes them) in a
    platoon of ``followers`` identical followers behind the lead (``lead_profile`` or ``lead``
    as in :func:`simulate`).

    Returns ``vehicles`` (per car the speed drop [m/s], amplification and smallest gap [m] at
    every position, and where a platoon failed) and the other keys of the command's JSON.
    """
    spec, tables = ("", {}) if vehicles is None else _cars(vehicles, "vehicles")
    lead_file, lead_text, lead_car = _lead(lead)
    return _result(_ddemap.growth(spec, tables, _integer("followers", followers, 1, 200), lead_profile or "", lead_file, lead_text, lead_car))


@_with_progress
def design(car, objective="sup-gamma", free=("k1", "k2"), bounds=None, margin=0.1, weights=None, starts=4, speed=None, ring=None, robust=False):
    """Gains of one car that minimise a stability objective within bounds (``ddemap design``).

    ``car``: one car, as :func:`classify` takes cars (``"C_max"``, ``"mycars.csv:Sedan"``, a
    one-row DataFrame, a fit's Result, ...). ``free``: the law parameters designed (the others,
    the delay and jam gap among them, held). ``bounds``: ``{name: (lo, hi)}`` for free
    parameters (default: a tenth to ten times the car's value). ``objective``:

    * ``"sup-gamma"``: sup_w |Gamma(iw)| |1 + i m w| with m = ``margin`` [s]; it is 1 exactly where
      every wave is damped at least as a first-order lag of m seconds damps it (the attenuation
      margin m* >= m), and then the result is the nearest such gains to the car's own;
    * ``"nearest"``: the smallest relative change sqrt(sum w_j^2 ((x_j - x0_j) / x0_j)^2)
      (``weights`` w_j, default 1) that gives an attenuation margin of at least ``margin``;
    * ``"peak"``: ||h||_1, the peak (L-infinity) norm;
    * ``"abscissa"``: the plant's spectral abscissa, or the ring's with ``ring`` (N or "inf").

    ``starts``: runs of the minimiser (the car's values and Halton points of the box).
    ``robust=True`` (a fitted car with its covariance, e.g. a :func:`calibrate` Result): the
    margin is asked of the worst point of the fit's 95 % ellipsoid of the held parameters
    (``--robust``; the result's ``robust`` has ``met`` and the designs' ``steps``).

    Returns ``gains`` ({name: value}), ``objective``, ``change``, ``attenuation_margin`` [s],
    ``margin_met``, ``infeasibility_proof`` (a proof that no gains of the box are string stable,
    or None), ``verdicts`` (the certified verdicts at the design, with :func:`string`'s keys),
    ``initial`` (the same at the car), ``starts`` and the other keys of the command's JSON.
    """
    spec, tables = _cars(car, "car")
    if isinstance(free, str):
        free = [f.strip() for f in free.split(",")]
    free = list(free)
    if not free or not all(isinstance(f, str) and f for f in free):
        raise ValueError("free = %r: expected parameter names, e.g. ('k1', 'k2')" % (free,))
    bound_list = []
    for name, value in (bounds or {}).items():
        try:
            lo, hi = value
        except (TypeError, ValueError):
            raise ValueError("bounds[%r] = %r: expected a pair (lo, hi)" % (name, value)) from None
        bound_list.append((str(name), _number("bounds[%r] lo" % name, lo), _number("bounds[%r] hi" % name, hi)))
    weights = [] if weights is None else [_number("weights", w) for w in weights]
    return _result(_ddemap.design(spec, tables, str(objective), free, bound_list, _number("margin", margin), weights,
                                  _integer("starts", starts, 1, 64), None if speed is None else _number("speed", speed),
                                  None if ring is None else _ring(ring), bool(robust)))


def _spec_text(spec):
    """A spec given as a TOML file (str or os.PathLike) or as TOML text (a str with a newline):
    (its text, the name it goes by in messages)."""
    if isinstance(spec, _os.PathLike) or (isinstance(spec, str) and "\n" not in spec):
        path = _os.fspath(spec)
        try:
            with open(path, encoding="utf-8") as f:
                return f.read(), path
        except OSError as e:
            raise ValueError("spec = %r: cannot read the file (%s)" % (path, e.strerror)) from None
    if isinstance(spec, str):
        return spec, "<spec>"
    raise TypeError("spec: %s: expected a TOML file (str or os.PathLike) or TOML text" % (type(spec).__name__,))


def _prefix(out, command, suffixes):
    """The output prefix as ``--out`` resolves it: a folder (existing, or ending in /) gets
    FOLDER/COMMAND; a known suffix is dropped; missing folders are created."""
    if not isinstance(out, (str, _os.PathLike)):
        raise TypeError("out: %s: expected a path prefix (str or os.PathLike)" % (type(out).__name__,))
    out = _os.fspath(out)
    if not out:
        raise ValueError("out = '': expected an output prefix (e.g. out='results/run1')")
    if out.endswith("/") or _os.path.isdir(out):
        out = _os.path.join(out, command)
    for suffix in suffixes:
        if out.endswith(suffix) and len(out) > len(suffix):
            out = out[: -len(suffix)]
            break
    folder = _os.path.dirname(out)
    if folder:
        _os.makedirs(folder, exist_ok=True)
    return out


@_with_progress
def chart(spec, out):
    """Renders a chart spec (``ddemap chart SPEC --out PREFIX``): ``spec`` is a TOML file (str or
    ``os.PathLike``; car files it names are found beside it) or TOML text (a str with a newline);
    writes PREFIX.svg and per panel K its grid PREFIX-panelK.csv and boundaries
    PREFIX-panelK-boundaries.csv. Returns ``panels``, ``seconds`` and ``files``.
    """
    text, source = _spec_text(spec)
    return _result(_ddemap.chart(text, source, _prefix(out, "chart", (".svg",))))


@_with_progress
def atlas(spec, out=None, allow_large=False):
    """An atlas (``ddemap atlas SPEC --out DIR``) computed in this process: ``spec`` is a TOML
    file (str or ``os.PathLike``) or TOML text (see docs/guide/atlases.md). Sized first: refused
    above about 600 s of computing or 2 GB of values unless ``allow_large=True`` (the command,
    which keeps only a chunk in memory, resumes and runs under MPI, is the tool for larger ones).

    Returns ``points``, ``shape`` (rings x axes), ``axes``, ``chunks``, ``regions`` (the count of
    each verdict class), ``uncertified``, ``seconds``, ``files``; ``fields``: every stored
    quantity (``string_stable``, ``sup_gamma``, ``spectral_abscissa``, ``region``, ...) as a NumPy
    array of that shape; ``coordinates``: ``ring`` (0 = infinity) and each axis's values. With
    ``out`` (a folder) it also writes ``atlas.h5`` and ``atlas.svg`` there, as the command does.
    """
    text, source = _spec_text(spec)
    prefix = ""
    if out is not None:
        folder = _os.fspath(out)
        if folder == "":
            raise ValueError("out = '': expected a folder")
        if _os.path.exists(folder) and not _os.path.isdir(folder):
            raise ValueError("out = %r: expected a folder" % (folder,))
        _os.makedirs(folder, exist_ok=True)
        prefix = _os.path.join(folder, "atlas")
    envelope, fields, coords = _ddemap.atlas(text, source, prefix, bool(allow_large))
    r = _result(envelope)
    r["fields"] = {k: _np.asarray(v) for k, v in fields.items()}
    r["coordinates"] = {k: _np.asarray(v) for k, v in coords.items()}
    return r


@_with_progress
def paper(out):
    """The seed paper's main job (``ddemap paper --out PREFIX``): the stability diagrams, the
    classification of the 14 settings and the disturbance growth, written under PREFIX (see
    docs/guide/charts.md). Returns the command's JSON keys."""
    return _result(_ddemap.paper(_prefix(out, "paper", (".svg", ".json"))))


def _nonlinear_problem(system, model, ring, parameters):
    """The problem arguments of equilibria, hopf and orbits, checked as the commands check them."""
    if (system is None) == (model is None):
        raise ValueError("expected one of system=FILE or model='ov'|'idm'|'acc' (with ring=N)")
    if system is not None:
        if ring is not None or parameters:
            raise ValueError("system takes the whole problem from the file: expected no ring or model parameters")
        return str(system), "", 0, {}
    if ring is None:
        raise ValueError("model=" + repr(model) + " needs ring=N: expected the number of cars")
    return "", str(model), _integer("ring", ring, 2, 2000), _parameters(parameters)


@_with_progress
def equilibria(par, from_, to, system=None, model=None, ring=None, count=4, max_points=400, par2=None, from2=None, to2=None, branch_point=None,
               **parameters):
    """A branch of equilibria of a nonlinear DDE in one parameter (``ddemap equilibria``).

    ``system``: a JSON file (variables, parameters, equations, equilibrium guess), or ``model``
    with ``ring`` N: ``"ov"``, the optimal-velocity ring with reaction delay (``alpha`` [1/s],
    ``tau`` [s], ``v0`` [m/s], ``h_st`` [m], ``headway`` [m]), or ``"idm"``, the intelligent
    driver model ring with sensing delay (``a``, ``b`` [m/s^2], ``v0`` [m/s], ``delta``, ``th``
    [s], ``eta`` [m], ``tau`` [s], ``gap`` [m]; ``th`` and ``tau`` required), or ``"acc"``, the
    paper's OVRV law with acceleration limits (``k1`` [1/s^2], ``k2`` [1/s], ``th`` [s], ``tau``
    [s], ``eta`` [m], ``gap`` [m] required; ``a_max``, ``a_min`` [m/s^2], default 2 and -3). The branch in the
    parameter ``par`` starts at ``from_`` (``--from``) and is followed by pseudo-arclength
    continuation (through folds) until the parameter leaves [from_, to] or ``max_points``;
    at every point the ``count`` rightmost roots of the linearisation decide stability; folds
    and Hopf points (a pair crossing the imaginary axis) are located by Newton.

    Returns ``points`` (columns ``par``, ``x``, ``abscissa``, ``unstable``, ``stable``, ...),
    ``folds``, ``hopf`` (``par``, ``omega`` [rad/s], ...), ``stop``: the command's JSON.

    With ``par2``, ``from2``, ``to2`` (``equilibria --par2``): the fold curves in (par, par2)
    through the branch's folds, with their cusp and Bogdanov-Takens points: ``branch`` (the
    branch in ``par``), ``curves`` (each with ``points``: ``par``, ``par2``, ``x``,
    ``cusp_test``, ``bt_test``; ``special``: ``kind`` ``cusp`` or ``bogdanov_takens``, ``par``,
    ``par2``, ``status``).

    ``branch_point`` K (``equilibria --branch-point K``): also the other branch of equilibria
    through the branch's branch point K (from 0), both halves joined through the point (the half
    away from ``to`` from its far end, then the half towards ``to``), as ``switched``
    (``from``: the point's ``index`` and ``par``; then the keys of a branch).
    """
    sys_, model_, n, p = _nonlinear_problem(system, model, ring, parameters)
    count = _integer("count", count, 1, 100)
    max_points = _integer("max_points", max_points, 2, 100000)
    return _result(_ddemap.equilibria(sys_, model_, n, p, par, _number("from_", from_), _number("to", to), count, max_points, par2 or "",
                                      None if from2 is None else _number("from2", from2), None if to2 is None else _number("to2", to2),
                                      None if branch_point is None else _integer("branch_point", branch_point, 0, 1000000)))


@_with_progress
def hopf(par, from_, to, system=None, model=None, ring=None, par2=None, from2=None, to2=None, max_points=400, **parameters):
    """Hopf points on the equilibrium branch with their criticality (``ddemap hopf``).

    The problem as in :func:`equilibria`; ``from_ < to``. Every Hopf point gets the first
    Lyapunov coefficient ``l1`` (DDE-BIFTOOL's normalisation: ||q|| = 1, p Delta'(i omega) q = 1,
    L1 = Re c1 / omega), its ``criticality`` (subcritical L1 > 0, supercritical L1 < 0),
    ``dre_dpar`` (d Re lambda / d par) and ``amplitude_coefficient`` (max - min of each variable
    of the bifurcating orbit per sqrt|par - par_H|). With ``par2``, ``from2``, ``to2``: the Hopf
    curves in (par, par2) through those points, the generalised Hopf points (L1 = 0), the double
    Hopf points (``double_hopf``: two pairs on the axis, where two curves cross; the second curve
    is traced from there) and the zero-Hopf points (``zero_hopf``) on them.
    Returns the command's JSON as Python objects.
    """
    sys_, model_, n, p = _nonlinear_problem(system, model, ring, parameters)
    max_points = _integer("max_points", max_points, 2, 100000)
    return _result(_ddemap.hopf(sys_, model_, n, p, par, _number("from_", from_), _number("to", to), par2 or "",
                                None if from2 is None else _number("from2", from2), None if to2 is None else _number("to2", to2),
                                max_points))


@_with_progress
def bistability(par, from_, to, par2, from2, to2, system=None, model=None, ring=None, degree=4, intervals=40, points=400, rows=200,
                **parameters):
    """Where stable stop-and-go waves coexist with a stable equilibrium in two parameters
    (``ddemap bistability``).

    The problem as in :func:`equilibria`; the box ``[from_, to] x [from2, to2]`` (the system's
    value of ``par2`` inside it). Returns ``hopf`` (the Hopf curves with criticality,
    generalised, double Hopf and zero-Hopf points, as :func:`hopf` with ``par2``),
    ``fold_curves`` (the curves of folds of periodic orbits) and ``cells`` (each with ``par``,
    ``par2``, ``equilibrium_stable``, ``stable_orbit``, ``bistable``, ``status``), as the
    command's JSON. ``degree``, ``intervals``: the orbits' mesh; ``points``: orbits per branch and
    points per curve direction; ``rows``: the lines that cut the box into cells.
    """
    sys_, model_, n, p = _nonlinear_problem(system, model, ring, parameters)
    return _result(_ddemap.bistability(sys_, model_, n, p, par, _number("from_", from_), _number("to", to), par2,
                                       _number("from2", from2), _number("to2", to2), _integer("degree", degree, 1, 20),
                                       _integer("intervals", intervals, 2, 10000), _integer("points", points, 2, 100000),
                                       _integer("rows", rows, 4, 10000)))


@_with_progress
def _guess_rows(guess):
    """times, states and a label of an orbit given as a CSV file, a table in memory
    (""" + _TYPES_TABLE + """: the first column t, then one per variable) or a pair (times, states)."""
    if isinstance(guess, tuple) and len(guess) == 2:
        times = [float(t) for t in guess[0]]
        states = [[float(v) for v in (row if hasattr(row, "__len__") else [row])] for row in guess[1]]
        return times, states, "data"
    if isinstance(guess, (str, bytes, _os.PathLike)):
        label = _os.fsdecode(guess)
        try:
            with open(label, encoding="utf-8-sig") as f:
                text = f.read()
        except OSError as e:
            raise ValueError("guess = %r: %s" % (label, e.strerror or e)) from None
    else:
        text = _table_text(guess, "guess")
        if text is None:
            raise ValueError("guess: expected a CSV file, %s or a pair (times, states)" % (_TYPES_TABLE,))
        label = "data"
    times, states = [], []
    for k, line in enumerate(text.splitlines(), 1):
        line = line.split("#", 1)[0].strip()
        if not line:
            continue
        fields = [x.strip() for x in line.split(",")]
        if not times and fields[0] and not (fields[0][0].isdigit() or fields[0][0] in "+-."):
            continue  # the header
        try:
            values = [float(x) for x in fields]
        except ValueError:
            raise ValueError("guess = %s, row %d: expected numbers, found %r" % (label, k, line)) from None
        if len(values) < 2:
            raise ValueError("guess = %s, row %d: expected t and one value per variable" % (label, k))
        if times and not values[0] > times[-1]:
            raise ValueError("guess = %s, row %d: t = %r: expected times increasing" % (label, k, values[0]))
        times.append(values[0])
        states.append(values[1:])
    return times, states, label


def orbits(par, from_, to, system=None, model=None, ring=None, hopf=0, degree=4, intervals=40, points=100, adapt=False,
           max_step=None, period_doubling=None, from_simulation=None, history=None, guess=None, par2=None, from2=None, to2=None,
           **parameters):
    """The branch of periodic orbits born at a Hopf point (``ddemap orbits``).

    The problem as in :func:`equilibria`; the equilibrium branch from ``from_`` to ``to`` gives
    the Hopf points, number ``hopf`` (from 0) starts the orbits: piecewise polynomials of degree
    ``degree`` on ``intervals`` mesh intervals, the period an unknown, at most ``points`` orbits.
    ``max_step`` (the command's ``--max-step``; default 0.1 when None): the largest step along
    the branch in its weighted norm, from 0.02 (the first step) to 1e6; a larger one covers the
    same stretch of the branch with fewer orbits (README, orbits).
    Returns ``points`` (``par``, ``period`` [time units of the system], ``min``, ``max`` per
    variable, ``stable``, ``multipliers``: Floquet multipliers as [re, im]), ``folds``,
    ``period_doublings``, ``tori``: the command's JSON. ``period_doubling`` (the command's
    ``--period-doubling``; an index from 0): also the branch of orbits of twice the period
    switched onto at that period doubling, as ``period_doubled`` (``from``: the doubling's
    ``par`` and ``period``; then the keys of a branch).
    Instead of a Hopf point the orbits can start (at ``par`` = ``from_``, followed towards ``to``)
    from the orbit a simulation settles on (``from_simulation`` = the run time T_END, from the
    constant state ``history``, default the equilibrium guess with the first variable raised by
    10 %; the command's ``--from-simulation``, ``--history``), or from an orbit ``guess``: a CSV
    file (t and one column per variable, the rows covering one period), a table in memory with
    those columns, or a pair (times, states) (``--guess``). Then ``start`` says how instead of
    ``hopf``. With ``par2``, ``from2``, ``to2`` (``--par2``): every fold of the branch continued
    as a curve of folds, every period doubling as a curve of period doublings and every torus
    bifurcation as a curve of tori in (par, par2), as ``fold_curves``, ``period_doubling_curves``
    and ``torus_curves`` (their points with ``rotation``, the angle of the multipliers on the
    unit circle).
    """
    sys_, model_, n, p = _nonlinear_problem(system, model, ring, parameters)
    step = None if max_step is None else _number("max_step", max_step)
    t_end = None if from_simulation is None else _number("from_simulation", from_simulation)
    hist = None if history is None else [_number("history", v) for v in (history if hasattr(history, "__len__") else [history])]
    times = states = None
    label = ""
    if guess is not None:
        times, states, label = _guess_rows(guess)
    return _result(_ddemap.orbits(sys_, model_, n, p, par, _number("from_", from_), _number("to", to),
                                  _integer("hopf", hopf, 0, 1000000), _integer("degree", degree, 1, 20),
                                  _integer("intervals", intervals, 2, 10000), _integer("points", points, 2, 100000), bool(adapt),
                                  step, None if period_doubling is None else _integer("period_doubling", period_doubling, 0, 1000000),
                                  t_end, hist, times, states, label, par2 or "",
                                  None if from2 is None else _number("from2", from2), None if to2 is None else _number("to2", to2)))