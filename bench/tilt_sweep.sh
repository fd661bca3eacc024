#!/usr/bin/env bash
# tilt_sweep.sh - the Y of the tests meshed by the stratmesh tool along axes tilted from
# its trunk's (z) by each TILT, toward 24 directions 15 degrees apart, each mesh checked
# against the Y's analytic surface by stratmesh_limb_shapes.
#
#   bench/tilt_sweep.sh [--points N] [TILT...]      (degrees; default 0.1 0.2 0.35 0.5 1 2 4 8 15)
#
# Prints one markdown table row per tilt: the axes whose branches were joined into one
# surface, those of them with no crossing pair of triangles, those meshed as one tube
# instead (the report's split_undone), and the largest crossing count among the joined.
# Tools: STRATMESH and LIMB_SHAPES, else build-bench/examples/cli/stratmesh and
# build-bench/bench/stratmesh_limb_shapes. Needs bash, python3 and a build with
# -DSTRATMESH_BUILD_BENCH=ON.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
stratmesh=${STRATMESH:-$root/build-bench/examples/cli/stratmesh}
shapes=${LIMB_SHAPES:-$root/build-bench/bench/stratmesh_limb_shapes}
points=20000
if [ "${1:-}" = "--points" ]; then points=$2; shift 2; fi
tilts=${*:-0.1 0.2 0.35 0.5 1 2 4 8 15}

dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
"$shapes" write "$dir" "$points"

echo "| tilt (degrees) | axes | joined | joined, no crossing pair | one tube | most crossing pairs when joined |"
echo "|---|---|---|---|---|---|"
for tilt in $tilts; do
    for direction in $(seq 0 15 345); do
        axis=$(python3 -c 'import math, sys
t, a = math.radians(float(sys.argv[1])), math.radians(float(sys.argv[2]))
print("%.9f,%.9f,1" % (math.tan(t) * math.cos(a), math.tan(t) * math.sin(a)))' "$tilt" "$direction")
        "$stratmesh" "$dir/y.ply" -o "$dir/y.off" --axis "$axis" --threads 1 --quiet \
            --report "$dir/report.json" > /dev/null 2>&1 || true
        "$shapes" check y "$dir/y.off" > "$dir/check.json"
        python3 -c 'import json, sys
r = json.load(open(sys.argv[1])); q = json.load(open(sys.argv[2]))
j = r.get("junction") or {}
joined = j.get("sides_joined", 0) > 0 and j.get("sides_left_apart", 1) == 0 and not r.get("split_undone")
print(int(joined), int(r.get("split_undone", False)), q["crossing_pairs"])' "$dir/report.json" "$dir/check.json"
    done | python3 -c 'import sys
rows = [tuple(map(int, line.split())) for line in sys.stdin]
joined = [c for j, u, c in rows if j]
print("| %s | %d | %d | %d | %d | %s |" % (sys.argv[1], len(rows), len(joined),
      sum(1 for c in joined if c == 0), sum(u for j, u, c in rows), max(joined) if joined else "-"))' "$tilt"
done
