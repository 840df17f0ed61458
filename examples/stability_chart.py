#!/usr/bin/env python3
"""The paper's stability diagrams in the (k1, k2) plane, drawn with matplotlib from ddemap.sweep.

OVRV, eta = 10 m, a ring of 22 cars; one panel per (tau, th) with tau in {0.1, 0.3, 0.6} s and
th in {1, 1.5, 2} s, as maps/paper.toml (which `ddemap chart` renders as SVG). Each panel: the
regions of the sweep (plant unstable, ring unstable, string unstable, string stable), the
boundary curves traced by continuation, and the paper's example point k1 = k2 = 0.2.

Usage (from the source folder, after the build):
    PYTHONPATH=build/python python3 examples/stability_chart.py chart.png [--count 101]
"""
import argparse

import matplotlib

matplotlib.use("Agg")  # no display needed
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.colors import ListedColormap  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402

import ddemap  # noqa: E402

REGIONS = ["plant unstable", "ring unstable", "string unstable", "string stable"]
COLOURS = ["#d73027", "#fc8d59", "#fee090", "#91bfdb"]  # as the SVG charts of ddemap


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("png", help="the PNG file to write")
    parser.add_argument("--count", type=int, default=101, help="grid points per axis (default 101, as maps/paper.toml)")
    args = parser.parse_args()

    taus, ths = [0.1, 0.3, 0.6], [1.0, 1.5, 2.0]
    fig, axes = plt.subplots(len(taus), len(ths), figsize=(10, 9), sharex=True, sharey=True)
    for i, tau in enumerate(taus):
        for j, th in enumerate(ths):
            r = ddemap.sweep(eta=10, tau=tau, th=th, k1=(0.01, 1, args.count), k2=(0.01, 1, args.count), ring=22)
            ax = axes[i][j]
            ax.pcolormesh(r["x"]["values"], r["y"]["values"], r["grid"]["region"], cmap=ListedColormap(COLOURS),
                          vmin=-0.5, vmax=3.5, shading="nearest")
            for c in r["curves"]:
                ax.plot(c["x"], c["y"], color="black" if c["kind"] == "hopf" else "#444444",
                        linestyle="-" if c["kind"] == "hopf" else "--", linewidth=0.9)
            if (tau, th) == (0.1, 1.5):
                ax.plot([0.2], [0.2], "o", color="black", markersize=5, label="paper example")
            ax.set_xlim(0.01, 1)
            ax.set_ylim(0.01, 1)
            ax.set_title("τ = %g s, $t_h$ = %g s" % (tau, th), fontsize=10)
            if i == len(taus) - 1:
                ax.set_xlabel("$k_1$ [1/s²]")
            if j == 0:
                ax.set_ylabel("$k_2$ [1/s]")
    handles = [Patch(color=c, label=n) for c, n in zip(COLOURS, REGIONS)]
    handles += [plt.Line2D([], [], color="black", label="Hopf boundary"),
                plt.Line2D([], [], color="#444444", linestyle="--", label="string boundary"),
                plt.Line2D([], [], marker="o", color="black", linestyle="", label="paper example")]
    fig.subplots_adjust(left=0.08, right=0.98, top=0.9, bottom=0.13, wspace=0.08, hspace=0.18)
    fig.legend(handles=handles, loc="lower center", ncol=4, fontsize=9, frameon=False)
    fig.suptitle("String stability diagrams in the (k₁, k₂) plane, OVRV, η = 10 m, ring of 22 cars\n(ddemap %s)" % ddemap.version)
    fig.savefig(args.png, dpi=110)
    print("wrote", args.png)


if __name__ == "__main__":
    main()
