#!/usr/bin/env bash
# roots --system at 10^3 and 10^4 states: the compact Krylov path, Spectra's full basis (the
# reference, 10^3 only) and SLEPc's NEP (NLEIGS), side by side (BENCHMARKS.md "Large sparse systems").
# SLEPc is a bench-only dependency: installed here (Debian libslepc-complex-dev), not by
# scripts/install-deps.sh; bench_slepc is built only when it is found.
#   bash bench/run_sparse_bench.sh [REPEAT] [TIMEOUT_S]      (SPECTRA=0 skips the full-basis reference)
set -u
cd "$(dirname "$0")/.."
repeat="${1:-3}"
limit="${2:-120}"
if ! pkg-config --exists slepc 2>/dev/null; then
    sudo=""; [ "$(id -u)" -ne 0 ] && sudo="sudo"
    $sudo apt-get install -y libslepc-complex-dev
fi
cmake -S . -B build >/dev/null
cmake --build build -j2 --target bench_sparse_system bench_slepc
mkdir -p out/sparse-bench
d=out/sparse-bench
# delayed reaction-diffusion u_t = d u_xx + a u - b u(t - tau) on (0, 1), d = 0.05, a = 0.5, b = 1, tau = 2:
# n grid points, lattice coefficient d (n + 1)^2; a second delay for the 3-delay variant
python3 bench/sparse_systems.py rd --nx 1000 --ny 1 --dx 50100.05 --dy 0 --out $d/rd1000.json
python3 bench/sparse_systems.py rd --nx 10000 --ny 1 --dx 5001000.05 --dy 0 --out $d/rd10000.json
python3 bench/sparse_systems.py rd --nx 1000 --ny 1 --dx 50100.05 --dy 0 --b 1,0.3,0.2 --tau 2,0.7,1.3 --out $d/rd1000_3.json
python3 bench/sparse_systems.py rd --nx 10000 --ny 1 --dx 5001000.05 --dy 0 --b 1,0.3,0.2 --tau 2,0.7,1.3 --out $d/rd10000_3.json
# a 2-D grid (40 x 25): the low modes are close together
python3 bench/sparse_systems.py rd --nx 40 --ny 25 --out $d/rd2d1000.json
python3 bench/sparse_systems.py rd --nx 100 --ny 100 --out $d/rd2d10000.json
# rings of 500 and 5,000 OVRV cars written out (k1 = 0.2, k2 = 0.4, th = 1.5, tau = 0.5)
python3 bench/sparse_systems.py ring --cars 500 --out $d/ring1000.json
python3 bench/sparse_systems.py ring --cars 5000 --out $d/ring10000.json
# a random network (x' = -x + W0 x + W1 x(t - 1), 4 entries per row): no structure, LUs fill in
python3 bench/sparse_systems.py net --n 1000 --out $d/net1000.json
for f in rd1000 rd1000_3 rd2d1000 ring1000 net1000 rd10000 rd10000_3 rd2d10000 ring10000; do
    echo "== $f: compact Krylov"
    timeout "$limit" build/bench/bench_sparse_system $d/$f.json --repeat "$repeat" || echo "(not done in $limit s)"
    case "$f:${SPECTRA:-1}" in *10000*|*:0) ;; *)
        echo "== $f: Spectra (full basis, the reference)"
        timeout "$limit" build/bench/bench_sparse_system $d/$f.json --arnoldi spectra --repeat 1 || echo "(not done in $limit s)";;
    esac
    echo "== $f: SLEPc NLEIGS"
    case $f in ring*) region=-0.2,0.2,3;; *) region=-0.5,1,3;; esac
    timeout "$limit" build/bench/bench_slepc $d/$f.json --nev 6 --region $region --repeat "$repeat" -nep_nleigs_pc_factor_mat_solver_type umfpack 2>&1 | grep -v "PETSC ERROR" || echo "(not done in $limit s)"
done
