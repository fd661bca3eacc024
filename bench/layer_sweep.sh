#!/usr/bin/env bash
# layer_sweep.sh - how stratmesh's mesh of one cloud fares over many layerings: one
# mesh-quality measurement per (axis, layer count), then a summary line.
#
#   bench/layer_sweep.sh [--ref REF.off] [--axes "z auto"] [--layers "4 6 8 12 16 24 32 48"]
#                        [--stratmesh PATH] [--checker PATH] CLOUD.ply [-- STRATMESH_OPTIONS...]
#
# Each run is the stratmesh tool with --layers N (and --axis A unless A is "auto"), --threads 1
# and STRATMESH_OPTIONS, then the mesh-quality checker (CHECKER --mesh MESH --cloud CLOUD
# [--ref REF]). One line per run: axis, layers, self-intersecting pairs, boundary loops, the
# mean distance to REF (the checker's chamfer_mean, relative to the diagonal) and the
# area ratio; then the summary: runs, the sum of self-intersecting pairs, the geometric mean
# of the mean distances and the worst one. A change to the centre choice or the bands is
# judged on that summary, not on one layering.
#
# The checker is not part of this repository: any mesh-quality checker that takes
# --mesh MESH.ply --cloud CLOUD.ply [--ref REF.off] and prints one JSON object with
# n_self_intersecting_pairs, n_boundary_loops, chamfer_mean (the mean distance between the
# mesh and REF, relative to REF's bounding-box diagonal) and area_ratio (the mesh's area over
# REF's). Give it with --checker PATH or the environment variable MESH_CHECKER.
#
# The stratmesh tool, unless given: build/examples/cli/stratmesh (relative to the source
# tree); the environment variable STRATMESH works too. Needs bash and python3. Exit status:
# 0 every run was measured, 1 a run or the checker failed (its line says so), 2 usage error.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
stratmesh=${STRATMESH:-$root/build/examples/cli/stratmesh}
checker=${MESH_CHECKER:-}
ref=""
axes="z auto"
layer_counts="4 6 8 12 16 24 32 48"
cloud=""
options=()

usage() {
  sed -n '5,24p' "$0" | sed 's/^# \{0,1\}//' >&2
  exit "${1:-2}"
}

while [ $# -gt 0 ]; do
  case "$1" in
    --ref) [ $# -ge 2 ] || usage; ref=$2; shift 2 ;;
    --axes) [ $# -ge 2 ] || usage; axes=$2; shift 2 ;;
    --layers) [ $# -ge 2 ] || usage; layer_counts=$2; shift 2 ;;
    --stratmesh) [ $# -ge 2 ] || usage; stratmesh=$2; shift 2 ;;
    --checker) [ $# -ge 2 ] || usage; checker=$2; shift 2 ;;
    -h|--help) usage 0 ;;
    --) shift; options=("$@"); break ;;
    -*) echo "layer_sweep.sh: unknown option $1" >&2; usage ;;
    *) [ -z "$cloud" ] || usage; cloud=$1; shift ;;
  esac
done
[ -n "$cloud" ] || usage
[ -f "$cloud" ] || { echo "layer_sweep.sh: no cloud $cloud" >&2; exit 2; }
[ -z "$ref" ] || [ -f "$ref" ] || { echo "layer_sweep.sh: no reference $ref" >&2; exit 2; }
[ -n "$checker" ] || { echo "layer_sweep.sh: no checker: set MESH_CHECKER or give --checker" >&2; exit 2; }
for tool in "$stratmesh" "$checker" python3; do
  command -v "$tool" > /dev/null || { echo "layer_sweep.sh: cannot run $tool" >&2; exit 2; }
done

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
checker_args=(--cloud "$cloud")
[ -z "$ref" ] || checker_args+=(--ref "$ref")

# The loop runs in a pipeline (a subshell): failures are found in its output afterwards.
for axis in $axes; do
  axis_args=()
  [ "$axis" = auto ] || axis_args=(--axis "$axis")
  for layers in $layer_counts; do
    if ! "$stratmesh" "$cloud" -o "$work/mesh.ply" --quiet --threads 1 --layers "$layers" \
         ${axis_args[@]+"${axis_args[@]}"} ${options[@]+"${options[@]}"} > "$work/log" 2>&1; then
      echo "axis=$axis layers=$layers stratmesh failed: $(tail -n 1 "$work/log")"
      continue
    fi
    if ! "$checker" --mesh "$work/mesh.ply" "${checker_args[@]}" > "$work/q.json" 2> "$work/log"; then
      echo "axis=$axis layers=$layers checker failed: $(tail -n 1 "$work/log")"
      continue
    fi
    python3 - "$axis" "$layers" "$work/q.json" <<'EOF'
import json, sys
q = json.load(open(sys.argv[3]))
mean = q.get("chamfer_mean")
print("axis=%s layers=%s si=%s boundary_loops=%s mean=%s area_ratio=%s" % (
    sys.argv[1], sys.argv[2], q.get("n_self_intersecting_pairs"), q.get("n_boundary_loops"),
    "%.5g" % mean if isinstance(mean, float) else "-",
    "%.4g" % q["area_ratio"] if isinstance(q.get("area_ratio"), float) else "-"))
EOF
  done
done | tee "$work/runs.txt"

python3 - "$work/runs.txt" <<'EOF'
import math, sys
runs = [dict(w.split("=", 1) for w in line.split() if "=" in w)
        for line in open(sys.argv[1]) if " failed" not in line]
si = sum(int(r["si"]) for r in runs if r.get("si", "None") != "None")
means = [float(r["mean"]) for r in runs if r.get("mean", "-") != "-"]
summary = "summary runs=%d si_sum=%d" % (len(runs), si)
if means:
    gmean = math.exp(sum(math.log(m) for m in means) / len(means))
    summary += " mean_gmean=%.5g mean_worst=%.5g" % (gmean, max(means))
print(summary)
EOF
if grep -q " failed" "$work/runs.txt"; then exit 1; fi
