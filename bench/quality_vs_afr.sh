#!/usr/bin/env bash
# quality_vs_afr.sh - how close stratmesh's mesh of a cloud is to a reference surface,
# next to CGAL's advancing-front reconstruction (stratmesh_afr_peer) of the same cloud.
#
#   bench/quality_vs_afr.sh [--ref REF.off] [--label NAME] [--keep DIR]
#                           [--stratmesh PATH] [--afr PATH] [--checker PATH]
#                           CLOUD.ply [-- STRATMESH_OPTIONS...]
#
# Runs the stratmesh tool (with STRATMESH_OPTIONS, e.g. --axis z --layers 8 --threads 1)
# and stratmesh_afr_peer on CLOUD, then the mesh-quality checker on both meshes
# (CHECKER --mesh MESH --cloud CLOUD [--ref REF]), and prints one JSON line per tool
# (stratmesh first). bench/README.md lists the fields.
#
# The checker is not part of this repository: any mesh-quality checker that takes those
# arguments and prints one JSON object with the fields this script copies: hausdorff,
# hausdorff_out_to_ref, hausdorff_ref_to_out, chamfer_mean, mean_out_to_ref,
# mean_ref_to_out, rms_out_to_ref, rms_ref_to_out (distances between the mesh and REF,
# relative to REF's bounding-box diagonal), area_ratio (the mesh's area over REF's),
# n_nonmanifold_edges, n_nonmanifold_vertices, n_components, n_boundary_loops,
# n_self_intersecting_pairs, n_self_intersecting_pairs_complete, cloud_frac_vertex_float
# (the share of CLOUD's points that are vertices), consistently_oriented, min_angle_p05
# (the 5th percentile of the triangles' smallest angles); a field it lacks comes out null,
# and an "error" field marks its run as failed. Give it with --checker PATH or the
# environment variable MESH_CHECKER.
#
# The other tools, unless given: the stratmesh tool at build/examples/cli/stratmesh and
# the peer at build/bench/stratmesh_afr_peer (relative to the source tree); environment
# variables STRATMESH and AFR_PEER work too. Needs bash and python3 (to merge the JSON).
# The meshes go to a temporary directory that is removed, or to --keep DIR.
# Exit status: 0 both tools ran and were measured, 1 a tool or the checker failed (its
# line says so), 2 usage error.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
stratmesh=${STRATMESH:-$root/build/examples/cli/stratmesh}
afr=${AFR_PEER:-$root/build/bench/stratmesh_afr_peer}
checker=${MESH_CHECKER:-}
ref=""
label=""
keep=""
cloud=""
options=()

usage() {
  sed -n '4,31p' "$0" | sed 's/^# \{0,1\}//' >&2
  exit "${1:-2}"
}

while [ $# -gt 0 ]; do
  case "$1" in
    --ref) [ $# -ge 2 ] || usage; ref=$2; shift 2 ;;
    --label) [ $# -ge 2 ] || usage; label=$2; shift 2 ;;
    --keep) [ $# -ge 2 ] || usage; keep=$2; shift 2 ;;
    --stratmesh) [ $# -ge 2 ] || usage; stratmesh=$2; shift 2 ;;
    --afr) [ $# -ge 2 ] || usage; afr=$2; shift 2 ;;
    --checker) [ $# -ge 2 ] || usage; checker=$2; shift 2 ;;
    -h|--help) usage 0 ;;
    --) shift; options=("$@"); break ;;
    -*) echo "quality_vs_afr.sh: unknown option $1" >&2; usage ;;
    *) [ -z "$cloud" ] || usage; cloud=$1; shift ;;
  esac
done
[ -n "$cloud" ] || usage
[ -f "$cloud" ] || { echo "quality_vs_afr.sh: no cloud $cloud" >&2; exit 2; }
[ -z "$ref" ] || [ -f "$ref" ] || { echo "quality_vs_afr.sh: no reference $ref" >&2; exit 2; }
[ -n "$checker" ] || { echo "quality_vs_afr.sh: no checker: set MESH_CHECKER or give --checker" >&2; exit 2; }
for tool in "$stratmesh" "$afr" "$checker"; do
  command -v "$tool" > /dev/null || { echo "quality_vs_afr.sh: cannot run $tool" >&2; exit 2; }
done
command -v python3 > /dev/null || { echo "quality_vs_afr.sh: needs python3" >&2; exit 2; }
[ -n "$label" ] || label=$(basename "$cloud" .ply)

if [ -n "$keep" ]; then
  mkdir -p "$keep"
  work=$keep
else
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
fi

checker_args=(--cloud "$cloud")
[ -z "$ref" ] || checker_args+=(--ref "$ref")

# stratmesh: its JSON report gives the library call's time, layers and folds.
sm_mesh=$work/$label.stratmesh.ply
sm_status=0
"$stratmesh" "$cloud" -o "$sm_mesh" --quiet --report "$work/$label.stratmesh.report.json" \
  ${options[@]+"${options[@]}"} > "$work/$label.stratmesh.log" 2>&1 || sm_status=$?
sm_q_status=0
if [ "$sm_status" -eq 0 ]; then
  "$checker" --mesh "$sm_mesh" "${checker_args[@]}" > "$work/$label.stratmesh.checker.json" \
    2> "$work/$label.stratmesh.checker.log" || sm_q_status=$?
fi

# The peer: its own JSON line gives the time of the CGAL call.
afr_mesh=$work/$label.afr.ply
afr_status=0
"$afr" "$cloud" -o "$afr_mesh" > "$work/$label.afr.json" 2> "$work/$label.afr.log" ||
  afr_status=$?
afr_q_status=0
if [ "$afr_status" -eq 0 ]; then
  "$checker" --mesh "$afr_mesh" "${checker_args[@]}" > "$work/$label.afr.checker.json" \
    2> "$work/$label.afr.checker.log" || afr_q_status=$?
fi

python3 - "$work" "$label" "$cloud" "$ref" \
  "$sm_status" "$sm_q_status" "$afr_status" "$afr_q_status" \
  ${options[@]+"${options[@]}"} <<'PY'
import json, os, sys

work, label, cloud, ref = sys.argv[1:5]
sm_status, sm_q_status, afr_status, afr_q_status = map(int, sys.argv[5:9])
options = sys.argv[9:]

def load(name):
    path = os.path.join(work, name)
    try:
        with open(path) as f:
            text = f.read().strip()
        if not text:
            return None
        try:
            return json.loads(text)  # the stratmesh report: one indented object
        except ValueError:
            return json.loads(text.splitlines()[-1])  # a tool's JSON line, after any output
    except (OSError, ValueError):
        return None

def tail(name):
    try:
        with open(os.path.join(work, name)) as f:
            lines = [l.strip() for l in f if l.strip()]
        return " / ".join(lines[-2:])
    except OSError:
        return ""

def figures(q):
    """The key figures of a checker line (None where the checker gave none)."""
    g = lambda k: q.get(k) if q else None
    return {
        "hausdorff": g("hausdorff"),
        "hausdorff_out_to_ref": g("hausdorff_out_to_ref"),
        "hausdorff_ref_to_out": g("hausdorff_ref_to_out"),
        "mean": g("chamfer_mean"),
        "mean_out_to_ref": g("mean_out_to_ref"),
        "mean_ref_to_out": g("mean_ref_to_out"),
        "rms_out_to_ref": g("rms_out_to_ref"),
        "rms_ref_to_out": g("rms_ref_to_out"),
        "area_ratio": g("area_ratio"),
        "nonmanifold_edges": g("n_nonmanifold_edges"),
        "nonmanifold_vertices": g("n_nonmanifold_vertices"),
        "components": g("n_components"),
        "boundary_loops": g("n_boundary_loops"),
        "self_intersecting_pairs": g("n_self_intersecting_pairs"),
        "self_intersections_complete": g("n_self_intersecting_pairs_complete"),
        "vertex_fraction": g("cloud_frac_vertex_float"),
        "consistently_oriented": g("consistently_oriented"),
        "min_angle_p05": g("min_angle_p05"),
    }

lines = []

# stratmesh
report = load(label + ".stratmesh.report.json") if sm_status == 0 else None
q = load(label + ".stratmesh.checker.json") if sm_status == 0 else None
row = {"tool": "stratmesh", "cloud": cloud, "ref": ref or None, "options": options}
if sm_status != 0:
    row["status"] = "error"
    row["error"] = "stratmesh exit %d: %s" % (sm_status, tail(label + ".stratmesh.log"))
elif sm_q_status != 0 or q is None or "error" in q:
    row["status"] = "error"
    row["error"] = "checker: %s" % ((q or {}).get("error") or tail(label + ".stratmesh.checker.log"))
else:
    row["status"] = "ok"
row["points"] = report["points"]["in"] if report else None
row["triangles"] = report["triangles"] if report else None
row["layers"] = report["layer_count"] if report else None
row["folds"] = report["folds"] if report else None
row["threads"] = report["options"]["threads"] if report else None
row.update(figures(q))
row["seconds"] = report["seconds"]["reconstruct"] if report else None
lines.append(row)

# CGAL's advancing front
peer = load(label + ".afr.json")
q = load(label + ".afr.checker.json") if afr_status == 0 else None
row = {"tool": "cgal_afr", "cloud": cloud, "ref": ref or None,
       "options": ["radius_ratio_bound=%g" % peer["radius_ratio_bound"],
                   "beta=%g" % peer["beta"]] if peer else []}
if afr_status != 0:
    row["status"] = "error"
    row["error"] = "stratmesh_afr_peer exit %d: %s" % (
        afr_status, (peer or {}).get("error") or tail(label + ".afr.log"))
elif afr_q_status != 0 or q is None or "error" in q:
    row["status"] = "error"
    row["error"] = "checker: %s" % ((q or {}).get("error") or tail(label + ".afr.checker.log"))
else:
    row["status"] = "ok"
row["points"] = peer["points"] if peer else None
row["triangles"] = peer["triangles"] if peer else None
row["layers"] = None
row["folds"] = None
row["threads"] = 1
row.update(figures(q))
row["seconds"] = peer["seconds"] if peer else None
lines.append(row)

for row in lines:
    print(json.dumps(row))
sys.exit(0 if all(r["status"] == "ok" for r in lines) else 1)
PY
