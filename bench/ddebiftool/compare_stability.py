#!/usr/bin/env python3
"""Point-by-point stability of DDE-BIFTOOL's orbits against ddemap's on the same branch.

    compare_stability.py DDEBIFTOOL.csv DDEMAP.csv

DDEBIFTOOL.csv: written by idm_ring_orbits.m with DDEBIFTOOL_POINTS=FILE (gap, period, nunst,
trivial_dist, absmu1..6); DDEMAP.csv: written by `bench_orbits --model idm --csv FILE 10` (gap,
period, nunst, max_nontrivial, trivial_distance). For every DDE-BIFTOOL orbit, the two ddemap
orbits whose gaps bracket its gap (ddemap's branch must be monotone in the gap there): the
number of nontrivial multipliers outside the unit circle of DDE-BIFTOOL's orbit against both
ddemap neighbours (equal to both: agree; the neighbours differ: a crossing lies between them,
then DDE-BIFTOOL's count must be one of theirs), and the period and the largest nontrivial |mu|
against ddemap's linearly interpolated at the same gap.
"""
import csv
import sys


def read(path):
    with open(path) as f:
        return [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    theirs, ours = read(sys.argv[1]), read(sys.argv[2])
    gaps = [p["gap"] for p in ours]
    if any(b <= a for a, b in zip(gaps, gaps[1:])):
        sys.exit("compare_stability.py: ddemap's branch is not increasing in the gap")
    agree = between = disagree = outside = 0
    worst_period = worst_mu = 0.0
    changes = []
    last = None
    for q in theirs:
        g = q["gap"]
        k = next((i for i in range(1, len(ours)) if ours[i]["gap"] >= g), None)
        if k is None or g < ours[0]["gap"]:
            outside += 1
            continue
        a, b = ours[k - 1], ours[k]
        w = (g - a["gap"]) / (b["gap"] - a["gap"])
        period = a["period"] + w * (b["period"] - a["period"])
        mu = a["max_nontrivial"] + w * (b["max_nontrivial"] - a["max_nontrivial"])
        worst_period = max(worst_period, abs(q["period"] - period) / period)
        worst_mu = max(worst_mu, abs(q["absmu1"] - mu) / mu)
        n = int(q["nunst"])
        if a["nunst"] == b["nunst"] == n:
            agree += 1
        elif a["nunst"] != b["nunst"] and n in (a["nunst"], b["nunst"]):
            between += 1
        else:
            disagree += 1
            print(f"differ: gap {g:.6f}: DDE-BIFTOOL {n}, ddemap {int(a['nunst'])} at {a['gap']:.6f} and {int(b['nunst'])} at {b['gap']:.6f}")
        if last is not None and n != last[1]:
            changes.append(f"{last[0]:.4f}..{g:.4f}: {last[1]} -> {n}")
        last = (g, n)
    print(f"DDE-BIFTOOL orbits compared {agree + between + disagree} (outside ddemap's range {outside}): same number of unstable "
          f"multipliers {agree}, at a crossing between ddemap's neighbours {between}, different {disagree}")
    print(f"largest relative difference: period {worst_period:.1e}, largest nontrivial |mu| {worst_mu:.1e}")
    print("DDE-BIFTOOL's count changes: " + ("; ".join(changes) if changes else "none"))
    ours_changes = [f"{ours[i - 1]['gap']:.4f}..{ours[i]['gap']:.4f}: {int(ours[i - 1]['nunst'])} -> {int(ours[i]['nunst'])}"
                    for i in range(1, len(ours)) if ours[i]["nunst"] != ours[i - 1]["nunst"]]
    print("ddemap's count changes:      " + ("; ".join(ours_changes) if ours_changes else "none"))
    return 1 if disagree else 0


if __name__ == "__main__":
    sys.exit(main())
