#!/usr/bin/env bash
# The main job: `ddemap paper` writes every figure and data file, the SVGs are valid XML with
# text elements, the classification finds all 14 settings string unstable, and the rendered
# maps committed in maps/ are the current output.
set -u
bin="${DDEMAP:?set DDEMAP to the ddemap binary}"
src="${SOURCE_DIR:?set SOURCE_DIR to the source tree}"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
pass=0; fail=0
ok() { pass=$((pass + 1)); }
bad() { echo "FAIL: $*"; fail=$((fail + 1)); }

if "$bin" paper --out "$tmp" >"$tmp/stdout.txt"; then ok; else bad "paper exit status"; fi
[ "$(grep -c 'stable    UNSTABLE  UNSTABLE' "$tmp/stdout.txt")" -eq 14 ] && ok || bad "14 settings ring and string unstable"
# --out DIR (an existing folder): the files are DIR/paper*, i.e. the prefix DIR/paper
for f in paper.svg paper-classification.svg paper-classification.csv paper-classification.json paper.json paper-panel1.csv paper-panel9-boundaries.csv paper-growth.csv; do
    [ -s "$tmp/$f" ] && ok || bad "missing $f"
done
for f in paper.svg classification.svg; do
    out="$tmp/${f/classification/paper-classification}"
    xmllint --noout "$out" && ok || bad "$f is not valid XML"
    grep -q '<text' "$out" && grep -q '<g id="legend"' "$out" && ok || bad "$f layers"
    cmp -s "$out" "$src/maps/$f" && ok || bad "maps/$f is not the current rendering (run: ddemap chart maps/${f%.svg}.toml --out maps/${f%.svg})"
done
ls "$tmp" | grep -q '\.part$' && bad "temporary files left" || ok
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
