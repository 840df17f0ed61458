#!/usr/bin/env bash
# Rejects an include of a higher layer (docs/code-layout.md): each layer may use only the layers
# listed before it. Checks include/ddemap/<layer>/ and src/<layer>/; exit 1 on a violation.
set -euo pipefail
cd "$(dirname "$0")/.."
layers=(core problem discretize solve traffic analysis study io)
status=0
for i in "${!layers[@]}"; do
    layer=${layers[$i]}
    for j in "${!layers[@]}"; do
        [ "$j" -le "$i" ] && continue
        higher=${layers[$j]}
        for dir in include/ddemap/$layer src/$layer; do
            [ -d "$dir" ] || continue
            if hits=$(grep -rnE "#include \"(ddemap/)?$higher/" "$dir"); then
                echo "layer violation: $layer includes $higher:"; echo "$hits"; status=1
            fi
        done
    done
done
# the library never includes the command-line front or the Python module
if hits=$(grep -rn '#include "\.\./\|apps/cli\|python/' include src 2>/dev/null); then
    echo "layer violation: library includes a front end:"; echo "$hits"; status=1
fi
[ $status -eq 0 ] && echo "layers: ok (${layers[*]})"
exit $status
