#!/usr/bin/env python3
"""Checks of `ddemap atlas` results (tests/cli/test_cli.sh), with h5py:

  atlas_check.py same A.h5 B.h5
      every dataset (values, shape, type), coordinate array and attribute of A equals B's bit
      for bit.
  atlas_check.py sweep A.h5 DDEMAP SWEEP_DIR
      every point of A against `ddemap sweep` on the same (k1, k2) window for each ring size and
      combination of the outer axes (an independent path through the command line: the sweep
      continues its roots along other rows), with the ring method A used (its "ring_method"
      attribute: "winding" is the sweep without boundaries, "modes" the sweep with boundaries,
      whose seeds need every mode's root): verdicts, certificates, root counts and modes
      exactly; the real quantities to 1e-8 relative (the same roots reached by Newton from other
      starting points agree to rounding; a quantity found by a maximisation over a grid to its
      stopping tolerance).
"""
import csv
import io
import subprocess
import sys
import tomllib

import h5py
import numpy as np

RTOL = 1e-8

UNIT_SUFFIXES = ("_rad_per_s", "_per_s2", "_per_s", "_mps2", "_mps", "_rad", "_s", "_m")


def unitless(column):
    """The quantity of a CSV column: its name without the unit suffix ddemap writes."""
    for suffix in UNIT_SUFFIXES:
        if column.endswith(suffix):
            return column[: -len(suffix)]
    return column


def walk(f):
    out = {}
    f.visititems(lambda name, obj: out.__setitem__(name, obj) if isinstance(obj, h5py.Dataset) else None)
    return out


def same(a_path, b_path):
    with h5py.File(a_path, "r") as a, h5py.File(b_path, "r") as b:
        da, db = walk(a), walk(b)
        assert sorted(da) == sorted(db), f"datasets differ: {sorted(da)} vs {sorted(db)}"
        for name in da:
            x, y = da[name][()], db[name][()]
            assert x.dtype == y.dtype and x.shape == y.shape, f"{name}: type or shape differs"
            assert x.tobytes() == y.tobytes(), f"{name}: values differ"
            assert dict(da[name].attrs) == dict(db[name].attrs), f"{name}: attributes differ"
        assert {k: a.attrs[k] for k in a.attrs} == {k: b.attrs[k] for k in b.attrs}, "root attributes differ"
        print(f"same: {len(da)} datasets equal bit for bit")


def text(v):
    return v.decode() if isinstance(v, bytes) else str(v)


def sweep(path, ddemap, sweep_dir):
    with h5py.File(path, "r") as f:
        dims = text(f.attrs["dimensions"]).split(",")
        model = text(f.attrs["model"])
        spec = tomllib.loads(text(f.attrs["spec"]))
        method = text(f.attrs["ring_method"])
        coords = {d: f["coordinates"][d][()] for d in dims}
        data = {k: f[k][()] for k in walk(f) if not k.startswith("coordinates")}
    fixed = spec.get("fixed", {})
    xname, yname = dims[-2], dims[-1]
    xs, ys = coords[xname], coords[yname]
    window = {a["name"]: a for a in spec["axis"]}  # the figure's axes are given as lo, hi, count
    outer = dims[:-2]  # ring, then the outer parameter axes
    compared = 0
    worst = 0.0
    for index in np.ndindex(*[len(coords[d]) for d in outer]):
        ring = int(coords["ring"][index[0]])
        assert method in ("winding", "modes"), f"ring_method attribute {method!r}"
        args = [ddemap, "sweep", "--model", model, "--ring", "inf" if ring == 0 else str(ring),
                "--format", "csv", "--quiet", "--out", sweep_dir + "/"]
        if method == "winding":
            args.append("--no-boundaries")
        for k, v in fixed.items():
            args += [f"--{k}", repr(float(v))]
        for d, i in zip(outer[1:], index[1:]):
            args += [f"--{d}", repr(float(coords[d][i]))]
        for name in (xname, yname):
            a = window[name]
            args += [f"--{name}", f"{float(a['lo'])!r}:{float(a['hi'])!r}:{a['count']}"]
        run = subprocess.run(args, capture_output=True, text=True)
        assert run.returncode in (0, 4), f"{' '.join(args)}: exit {run.returncode}: {run.stderr}"
        # the sweep's columns carry their units (k1_per_s2, spectral_abscissa_per_s): read by quantity
        rows = [{unitless(k): v for k, v in r.items()} for r in csv.DictReader(io.StringIO(run.stdout))]
        assert len(rows) == len(xs) * len(ys), "the sweep has another number of points"
        for row in rows:
            ix = int(np.flatnonzero(xs == float(row[xname]))[0])
            iy = int(np.flatnonzero(ys == float(row[yname]))[0])
            at = tuple(index) + (ix, iy)
            for flag in ("plant_stable", "ring_stable", "string_stable", "certified"):
                assert bool(data[flag][at]) == (row[flag] == "true"), f"{flag} differs at {at}"
            for count in ("unstable_roots", "abscissa_mode"):
                want = -1 if row[count] == "" else int(row[count])
                assert int(data[count][at]) == want, f"{count} differs at {at}: {data[count][at]} vs {want}"
            for q in ("spectral_abscissa", "sup_gamma", "omega_peak", "plant_abscissa", "lowfreq_margin", "peak_gain"):
                a, b = float(data[q][at]), float(row[q])
                err = abs(a - b) / max(1.0, abs(b))
                worst = max(worst, err)
                assert err <= RTOL, f"{q} differs at {at}: {a!r} vs {b!r}"
            compared += 1
    assert compared == data["region"].size, "not every point was compared"
    print(f"sweep: {compared} points agree with ddemap sweep, ring method {method} (largest relative difference {worst:.2e})")


if __name__ == "__main__":
    if len(sys.argv) == 4 and sys.argv[1] == "same":
        same(sys.argv[2], sys.argv[3])
    elif len(sys.argv) == 5 and sys.argv[1] == "sweep":
        sweep(sys.argv[2], sys.argv[3], sys.argv[4])
    else:
        sys.exit("usage: atlas_check.py same A.h5 B.h5 | sweep A.h5 DDEMAP SWEEP_DIR")
