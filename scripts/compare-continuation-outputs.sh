#!/usr/bin/env bash
# Runs the README examples of the continuation commands (equilibria, hopf, orbits,
# orbits --wave, sweep) and a few more that reach other paths (rejected steps, the homotopy of
# long waves) with two builds of ddemap and compares their stdout, stderr, exit codes and
# written files byte for byte (wall-clock times masked). Used to check that a refactoring of
# the continuation code leaves every output unchanged.
#   scripts/compare-continuation-outputs.sh OLD_DDEMAP NEW_DDEMAP [WORKDIR]
# Exit 0 when everything is identical, 1 otherwise (the differences are printed).
set -uo pipefail
old=$(realpath "$1") new=$(realpath "$2")
src=$(cd "$(dirname "$0")/.." && pwd)
work=${3:-$(mktemp -d)}
commands=(
  "sweep --th 1.5 --tau 0.1 --k1 0.01:1:200 --k2 0.01:1:200 --out chart"
  "equilibria --model ov --ring 5 --par headway --from 1.2 --to 3"
  "hopf --model idm --ring 5 --th 1.2 --tau 0.6 --a 1.1 --b 1.6 --v0 32 --par gap --from 6 --to 40"
  "equilibria --system examples/neuron.json --par a21 --from 0.3 --to 2"
  "hopf --system examples/wright.json --par alpha --from 1 --to 2"
  "hopf --system examples/duffing.json --par tau --from 0 --to 10"
  "hopf --system examples/duffing.json --par tau --from 0 --to 20 --par2 b --from2 0 --to2 0.6"
  "hopf --model ov --ring 3 --par headway --from 1.2 --to 3"
  "hopf --system examples/neuron.json --par a21 --from 0.3 --to 2 --par2 taus --from2 0 --to2 10 --format csv"
  "orbits --system wright.json --par alpha --from 1 --to 2.5 --points 20"
  "orbits --system examples/neuron.json --par a21 --from 0.3 --to 2 --points 30"
  "orbits --system examples/duffing.json --par tau --from 0 --to 20 --hopf 1 --intervals 30 --points 12"
  "orbits --model ov --ring 5 --par headway --from 2 --to 3.5 --hopf 1 --points 120 --svg maps/ov-ring-bistability.svg"
  "orbits --model ov --ring 5 --wave 1 --par headway --from 3.5 --to 2 --points 30"
  "orbits --model idm --ring 5 --th 1.2 --tau 0.6 --wave 1 --par gap --from 6 --to 22 --points 300 --max-step 1"
  "orbits --model ov --ring 1000 --wave 10 --par headway --from 3.5 --to 2 --initial-step 0.001 --points 30 --intervals 160"
  # not README examples: paths the examples above do not reach (the same ring on the default 40
  # intervals stops as unresolved; long waves reached by the homotopy in K / N, its message in JSON)
  "orbits --model ov --ring 1000 --wave 10 --par headway --from 3.5 --to 2 --initial-step 0.001 --points 30"
  "orbits --model ov --ring 1000 --wave 1 --par headway --from 3.5 --to 2 --points 30 --format json"
  "orbits --model ov --ring 1000 --wave 2 --par headway --from 3.5 --to 2 --points 30 --intervals 80 --format json"
  # rejected steps (the README examples above never reject one): orbits (and a branch that ends
  # below min_step, exit 4), the curve of Hopf points and the stability boundaries
  # (continue_branch), travelling waves
  "orbits --system wright.json --par alpha --from 1 --to 4 --points 60 --max-step 5"
  "hopf --system examples/duffing.json --par tau --from 0 --to 40 --par2 b --from2 -2 --to2 2"
  "boundary --th 1.0 --tau 0.5 --k1 0.001:2 --k2 0.001:2 --out curves"
  "orbits --model ov --ring 1000 --wave 1 --par headway --from 3.5 --to 1.2 --points 100 --format json"
  "orbits --model ov --ring 201 --wave 3 --par headway --from 3.5 --to 1.2 --points 100 --max-step 5"
)
# wall-clock times are the only outputs allowed to differ: the timings of the sweep and the
# progress lines on stderr (printed once a run has taken a second)
mask() { sed -E -e 's/in [0-9.e+-]+ s \([0-9.e+-]+ points\/s/in T s (R points\/s/' \
                -e 's/"(seconds|points_per_second|wall_seconds)": *[0-9.e+-]+/"\1": T/g' \
                -e '/^ddemap: [a-z]+: .*\([0-9.]+ [a-z]+(, about [0-9.e+-]+ [a-z]+ left|; time left unknown)?\)$/d' "$1"; }
run() {  # binary dir
    mkdir -p "$2/maps" && cd "$2" || exit 3
    ln -sfn "$src/examples" examples
    echo '{"variables": ["y"], "parameters": {"alpha": 1}, "equations": ["-alpha*y(t - 1)*(1 + y)"], "equilibrium": [0]}' > wright.json
    local i=0
    for c in "${commands[@]}"; do
        i=$((i + 1))
        local t0=$SECONDS
        # shellcheck disable=SC2086
        "$1" $c > "out$i.stdout" 2> "out$i.stderr"
        echo "$?" > "out$i.rc"
        echo "  [$i] $((SECONDS - t0)) s rc $(cat "out$i.rc"): ddemap $c" >&2
    done
}
echo "old: $old" >&2; run "$old" "$work/old"
echo "new: $new" >&2; run "$new" "$work/new"
status=0
cd "$work/old" || exit 3
for f in $(find . -type f | sort); do
    if [ ! -f "../new/$f" ]; then echo "only in old: $f"; status=1; continue; fi
    if ! cmp -s "$f" "../new/$f" && ! cmp -s <(mask "$f") <(mask "../new/$f"); then
        echo "differs: $f"; diff <(mask "$f") <(mask "../new/$f") | head -20; status=1
    fi
done
cd "$work/new" && for f in $(find . -type f | sort); do [ -f "../old/$f" ] || { echo "only in new: $f"; status=1; }; done
[ $status -eq 0 ] && echo "identical: ${#commands[@]} commands, $(find "$work/old" -type f | wc -l) files (times masked)"
exit $status
