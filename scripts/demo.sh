#!/usr/bin/env bash
# Installs what is missing, builds the program (only it, with progress), and runs the main job
# on built-in data: the seed paper's calibration table classified (on stdout) and every figure
# and data file in out/paper.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh ddemap_cli
out=out/paper
mkdir -p "$out"
build/ddemap paper --out "$out"
