#!/usr/bin/env bash
# limbs.sh - the shapes with limbs of the tests, meshed by the stratmesh tool (by default,
# and along z, the trunk's axis) and by CGAL's advancing front (stratmesh_afr_peer), each
# checked against the shape's analytic surface by stratmesh_limb_shapes.
#
#   bench/limbs.sh [--points N] [SHAPE...]      (shapes: y branched hand animal tee twice
#                                                elbow u_bend coil torus)
#
# Prints one markdown table row per shape and mesher: the mean distance to the surface
# over the bounding box's diagonal, the area ratio, components, crossing pairs, points
# that are no vertex, and the seconds (the tool: its whole run with --threads 1, reading and
# writing included; the peer: its library call, as it reports).
# Tools: STRATMESH, AFR_PEER and LIMB_SHAPES, else build-bench/examples/cli/stratmesh,
# build-bench/bench/stratmesh_afr_peer and build-bench/bench/stratmesh_limb_shapes.
# Needs bash, python3 and a build with -DSTRATMESH_BUILD_BENCH=ON -DSTRATMESH_BENCH_CGAL=ON.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
stratmesh=${STRATMESH:-$root/build-bench/examples/cli/stratmesh}
afr=${AFR_PEER:-$root/build-bench/bench/stratmesh_afr_peer}
shapes=${LIMB_SHAPES:-$root/build-bench/bench/stratmesh_limb_shapes}
points=20000
if [ "${1:-}" = "--points" ]; then points=$2; shift 2; fi
names=${*:-y branched hand animal tee twice elbow u_bend coil torus}
export LIMB_POINTS=$points

dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
"$shapes" write "$dir" "$points"

row() {  # row SHAPE MESHER SECONDS MESH.off
    "$shapes" check "$1" "$4" | python3 -c '
import json, sys
q = json.loads(sys.stdin.read())
print("| %s | %s | %.5f | %.2f | %d | %d | %d | %.3f |" % (sys.argv[1], sys.argv[2], q["mean"],
      q["area"], q["components"], q["crossing_pairs"], q["unused"], float(sys.argv[3])))' "$1" "$2" "$3"
}

seconds() {  # seconds COMMAND...: runs it, prints its wall time
    local start end
    start=$(date +%s.%N)
    "$@" > /dev/null 2>&1 || true
    end=$(date +%s.%N)
    python3 -c "import sys; print(float(sys.argv[1]) - float(sys.argv[2]))" "$end" "$start"
}

echo "| shape | mesher | mean distance | area ratio | components | crossing pairs | unused | seconds |"
echo "|---|---|---|---|---|---|---|---|"
for name in $names; do
    cloud=$dir/$name.ply
    t=$(seconds "$stratmesh" "$cloud" -o "$dir/$name-default.off" --threads 1 --quiet)
    row "$name" "stratmesh" "$t" "$dir/$name-default.off"
    t=$(seconds "$stratmesh" "$cloud" -o "$dir/$name-z.off" --axis z --threads 1 --quiet)
    row "$name" "stratmesh --axis z" "$t" "$dir/$name-z.off"
    t=$("$afr" "$cloud" -o "$dir/$name-afr.off" | python3 -c 'import json, sys; print(json.loads(sys.stdin.read())["seconds"])')
    row "$name" "advancing front" "$t" "$dir/$name-afr.off"
done
