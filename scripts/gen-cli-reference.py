#!/usr/bin/env python3
"""Writes docs/reference/cli.md, the command reference, from the --help texts of a built ddemap.

Usage: scripts/gen-cli-reference.py DDEMAP_BINARY [OUT.md]     (OUT.md: docs/reference/cli.md)

For every command that `ddemap --help` lists: a section `## COMMAND` with a one-paragraph summary
(SUMMARIES below, written by hand: keep them in step when a command changes), a table of its
flags (flag, value, default, meaning with units, parsed from the help text), and the help text
itself. Rerun it after changing a command's flags; tests/cli/test_cli_reference.py checks that
the tables and `--help` name the same flags.
"""
import os
import re
import subprocess
import sys

GUIDE = "../guide/"

SUMMARIES = {
    "roots": "Rightmost characteristic roots, with residuals and a verdict, of one of three problems: "
             "a ring of N identical cars (`--ring N`, up to 10^9 cars, or `inf`), a mixed ring in which "
             "every car has its own law and parameters (`--fleet`), or any linear DDE read from a JSON file "
             "(`--system`, which may also be a nonlinear system file, then linearised at its equilibrium). "
             "Guides: [string stability](" + GUIDE + "string-stability.md), [platoons and mixed fleets]("
             + GUIDE + "platoons.md), [linear systems](" + GUIDE + "linear-systems.md).",
    "string": "Plant and string stability of one car law from its head-to-tail transfer function: the plant's "
              "rightmost root, sup |Gamma(iw)| and its frequency, the low-frequency coefficient c2, and with "
              "`--ring` the ring verdict. Guide: [string stability](" + GUIDE + "string-stability.md).",
    "classify": "Plant, ring and string verdicts of a list of OVRV vehicles: the seed paper's 14 calibrated "
                "settings by default, or a vehicle CSV such as `calibrate` writes. With the covariance columns "
                "of a fit the verdicts come with probabilities. Guides: [string stability]("
                + GUIDE + "string-stability.md), [calibration](" + GUIDE + "calibration.md).",
    "design": "Gains (or any law parameters, `--free`) of one car that minimise a stability objective within "
              "bounds: the weighted H-infinity norm sup |Gamma(iw)| |1 + i m w|, the peak norm ||h||_1, the plant's "
              "or a ring's spectral abscissa, or the nearest gains with an attenuation margin of at least m seconds; "
              "the verdicts at the car and at the design, certified. Guide: [gain design](" + GUIDE + "design.md).",
    "sweep": "A grid over two model parameters (each `LO:HI:COUNT`): spectral abscissa, unstable roots, "
             "sup |Gamma| and the three verdicts at every point, the stability boundaries traced through the "
             "window, and the chart as SVG. Guide: [stability charts](" + GUIDE + "charts.md).",
    "boundary": "Only the stability boundaries in a window of two parameters (each `LO:HI`), traced by "
                "pseudo-arclength continuation: plant and ring Hopf curves, the low-frequency string curve "
                "c2 = 0 and the peak curves. Guide: [stability charts](" + GUIDE + "charts.md).",
    "chart": "Renders a chart spec (TOML, see `maps/`) into one SVG of one or more panels, each a sweep with "
             "its boundaries and labelled markers. Guide: [stability charts](" + GUIDE + "charts.md).",
    "paper": "The seed paper's main job in one command: the classification table on stdout, and its "
             "figures (stability diagrams, classification chart, growth figure) with their data under the "
             "output prefix. Guide: [stability charts](" + GUIDE + "charts.md).",
    "simulate": "Nonlinear simulation of a platoon of OVRV followers behind a lead speed profile (built in or "
                "a CSV), with ACC disengagement and collision events. Guide: [platoons](" + GUIDE + "platoons.md).",
    "growth": "The seed paper's disturbance-growth study: every setting of the calibration table in "
              "platoons of 1 to 15 followers behind the lead profile; speed drop, amplification and minimum "
              "gap per position. Guide: [platoons](" + GUIDE + "platoons.md).",
    "calibrate": "Fits OVRV (k1, k2, th, tau, eta) to measured car-following traces by least squares with "
                 "exact sensitivities: one fit per file, one joint fit to several runs (`--joint`), or per "
                 "car on its training runs, tested on the others (`--runs`), with 95 % intervals, warnings "
                 "and an optional report. Guide: [calibration](" + GUIDE + "calibration.md).",
    "mix": "Penetration-rate study: the spectral abscissa of a ring of N cars in which a fraction p are of "
           "type X and the rest of type Y, for a range of p. Guide: [platoons and mixed fleets]("
           + GUIDE + "platoons.md).",
    "equilibria": "A branch of equilibria of a nonlinear DDE (a system file with expressions, or a built-in "
                  "ring `ov` or `idm`) in one parameter, by pseudo-arclength continuation, with the rightmost "
                  "roots at every point and the folds, branch points and Hopf points located. Guide: "
                  "[bifurcations](" + GUIDE + "bifurcations.md).",
    "hopf": "The Hopf points on a branch of equilibria with their criticality (first Lyapunov coefficient), "
            "crossing speed and the predicted orbit amplitude; with `--par2` the Hopf curves in two parameters "
            "and their generalised Hopf points. Guide: [bifurcations](" + GUIDE + "bifurcations.md).",
    "atlas": "The sweep's quantities over a grid of two to five parameters and a list of ring sizes, on "
             "OpenMP threads and MPI ranks, resumable after an interruption; writes HDF5 and an SVG. "
             "Guide: [atlases](" + GUIDE + "atlases.md).",
    "orbits": "The branch of periodic orbits born at a Hopf point, with periods, amplitudes, Floquet "
              "multipliers and the folds, period doublings and tori located; with `--wave K` the travelling "
              "waves of a ring in a reduced form whose cost does not depend on N; with `--par2` every fold of "
              "orbits followed as a curve in two parameters. Guide: [bifurcations]("
              + GUIDE + "bifurcations.md).",
    "bistability": "Where stable periodic orbits (stop-and-go waves) coexist with a stable equilibrium (uniform "
                   "flow) in two parameters: the Hopf curves with their criticality and generalised Hopf points, "
                   "the curves of folds of periodic orbits, and the cells of the box they cut, each decided by a "
                   "one-parameter slice; the chart as SVG. Guide: [bifurcations](" + GUIDE + "bifurcations.md).",
}

OPTION = re.compile(r"^  (-\S.*?|[A-Za-z][\w.]*( .*?)?)(?:\s{2,}(\S.*))?$")
NAMES = re.compile(r"--[a-z0-9][a-z0-9-]*")
PLACEHOLDER = re.compile(r"^[A-Z][A-Z0-9:,.|]*$")


def run_help(binary, *args):
    text = subprocess.run([binary, *args, "--help"], capture_output=True, text=True, check=True).stdout
    return re.sub(r"Usage: \S*ddemap", "Usage: ddemap", text).rstrip("\n")


def commands(top_help):
    out, inside = [], False
    for line in top_help.splitlines():
        if line.startswith("Subcommands:"):
            inside = True
            continue
        if inside:
            m = re.match(r"^  (\S+)\s", line)
            if m:
                out.append(m.group(1))
            elif line.strip() and not line.startswith(" "):
                break
    return out


def options(help_text):
    """(group, left column, description) for every option and positional of a help text."""
    rows, group, current = [], None, None
    for line in help_text.splitlines():
        if not line.strip():
            current = None
            continue
        if not line.startswith(" "):
            group = line.rstrip(":") if line.endswith(":") else None
            current = None
            continue
        if group in (None, "Usage") or line.startswith("Usage"):
            continue
        if line.startswith(" " * 6) and current is not None:  # a wrapped description
            current[2] = (current[2] + " " + line.strip()).strip()
            continue
        m = OPTION.match(line)
        if m:
            current = [group, m.group(1).strip(), (m.group(3) or "").strip()]
            rows.append(current)
    return rows


def split_left(left):
    """'--ring N|inf=22' -> ('--ring', 'N|inf', '22', required)."""
    required = left.endswith(" REQUIRED")
    if required:
        left = left[: -len(" REQUIRED")]
    parts = left.split(" ", 1)
    names, rest = parts[0], (parts[1] if len(parts) > 1 else "")
    value, default = rest, ""
    if "=" in rest:
        head, tail = rest.split("=", 1)
        if PLACEHOLDER.match(tail):
            value = rest  # NAME=LO:HI,... is a placeholder, not a default
        else:
            value, default = head, tail
    return names, value, default, required


def cell(text):
    return text.replace("|", "\\|") if text else ""


def table(rows):
    out = ["| flag | value | default | meaning |", "|---|---|---|---|"]
    for group, left, desc in rows:
        names, value, default, required = split_left(left)
        if not names.startswith("-"):
            continue
        flags = ", ".join("`%s`" % n for n in names.split(","))
        if required:
            default = "required"
        elif not default:
            default = "see meaning" if re.search(r"\bdefault|\brequired", desc) else ("off" if not value else "not set")
        else:
            default = "`%s`" % default
        out.append("| %s | %s | %s | %s |" % (flags, ("`%s`" % cell(value)) if value else "", cell(default), cell(desc)))
    return out


def positionals(rows):
    out = []
    for group, left, desc in rows:
        if group == "Positionals":
            out.append("* `%s`: %s" % (left, desc))
    return out


def main():
    binary = sys.argv[1]
    out_path = sys.argv[2] if len(sys.argv) > 2 else os.path.join(os.path.dirname(__file__), "..", "docs", "reference", "cli.md")
    top = run_help(binary)
    cmds = commands(top)
    missing = [c for c in cmds if c not in SUMMARIES]
    if missing:
        sys.exit("gen-cli-reference.py: no summary for %s: add one to SUMMARIES" % ", ".join(missing))
    version = subprocess.run([binary, "--version"], capture_output=True, text=True).stdout.strip()
    lines = [
        "# Command reference",
        "",
        "<!-- Generated by scripts/gen-cli-reference.py from the --help texts of ddemap %s; do not edit by hand:"
        " change the summaries in the script or the help texts in apps/cli/, then regenerate. -->" % version,
        "",
        "Every command of `ddemap` with every flag: its value, its default and its meaning with units, "
        "as `ddemap COMMAND --help` prints them (the help text follows each table). The flags shared "
        "by several commands (`--format`, `--out`, the model flags, `--ring`, `--allow-large`, "
        "`--quiet`) behave the same everywhere: [outputs.md](outputs.md). Statuses and exit codes: "
        "[verdicts.md](../verdicts.md). Where a help text says \"see README\", the topic is in the "
        "[user guides](../index.md).",
        "",
        "Commands: " + ", ".join("[%s](#%s)" % (c, c) for c in cmds) + ".",
        "",
        "## ddemap",
        "",
        "The program itself: `ddemap --help` lists the commands, `ddemap --version` prints the version.",
        "",
    ]
    lines += table(options(top))
    lines += ["", "```text", top, "```", ""]
    for c in cmds:
        text = run_help(binary, c)
        rows = options(text)
        lines += ["## " + c, "", SUMMARIES[c], ""]
        pos = positionals(rows)
        if pos:
            lines += ["Arguments:", ""] + pos + [""]
        lines += table(rows)
        lines += ["", "<details><summary><code>ddemap %s --help</code></summary>" % c, "", "```text", text, "```", "", "</details>", ""]
    os.makedirs(os.path.dirname(os.path.abspath(out_path)), exist_ok=True)
    with open(out_path, "w", encoding="utf-8") as f:
        f.write("\n".join(lines))
    print("wrote %s (%d commands)" % (out_path, len(cmds)))


if __name__ == "__main__":
    main()
