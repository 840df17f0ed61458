#!/usr/bin/env bash
# Installs what is missing, builds, and runs the main job on built-in data: the seed paper's
# example point and its calibration table (every vehicle setting), with verdicts.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh >/dev/null
bin=build/ddemap
echo "== The paper's example point (th = 1.5 s, tau = 0.1 s, k1 = k2 = 0.2): a ring of 22 cars"
$bin roots --k1 0.2 --k2 0.2 --th 1.5 --tau 0.1 --ring 22 --count 4
echo
echo "== Its string stability"
$bin string --k1 0.2 --k2 0.2 --th 1.5 --tau 0.1 --ring inf
echo
echo "== The paper's calibration table (Gunter et al.), every vehicle setting"
$bin classify
