#!/usr/bin/env bash
# end_to_end.sh - the command line with no options against CGAL's advancing-front
# reconstruction (stratmesh_afr_peer) on the same clouds, in one run.
#
#   bench/end_to_end.sh [--runs N] [--build DIR] [--keep DIR]
#
# Writes the bumpy tubes of stratmesh_bench's default-1e5 and default-1e6 cases as binary
# PLY (stratmesh_bench --write-cloud), then for each: the tool with no options, end to end
# (read, reconstruct, write; wall time of the process, the median of N runs, default 3),
# and the peer once (its library call alone, reading and writing left out). Prints one
# JSON line per cloud: points, tool_seconds (median), tool_min_seconds, peer_seconds and
# ratio = peer_seconds / tool_seconds (above 1: the tool is faster).
#
# Needs a build with the benchmark and its CGAL peer (libcgal-dev):
#   cmake -S . -B build-bench -DCMAKE_BUILD_TYPE=Release -DSTRATMESH_BUILD_BENCH=ON \
#     -DSTRATMESH_BENCH_CGAL=ON -DSTRATMESH_BUILD_TESTS=OFF
#   cmake --build build-bench -j2 --target stratmesh_cli stratmesh_bench stratmesh_afr_peer
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
build=$root/build-bench
runs=3
keep=""
while [ $# -gt 0 ]; do
  case "$1" in
    --runs) runs=$2; shift 2 ;;
    --build) build=$2; shift 2 ;;
    --keep) keep=$2; shift 2 ;;
    *) sed -n '4p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2 ;;
  esac
done
tool=$build/examples/cli/stratmesh
bench=$build/bench/stratmesh_bench
peer=$build/bench/stratmesh_afr_peer
for program in "$tool" "$bench" "$peer"; do
  [ -x "$program" ] || { echo "end_to_end.sh: $program is not built (see the header)" >&2; exit 2; }
done
work=${keep:-$(mktemp -d)}
mkdir -p "$work"
[ -n "$keep" ] || trap 'rm -rf "$work"' EXIT

now() { date +%s.%N; }

for name in default-1e5 default-1e6; do
  cloud=$work/$name.ply
  "$bench" --write-cloud "$name" "$cloud"
  times=()
  for ((k = 0; k < runs; ++k)); do
    start=$(now)
    "$tool" "$cloud" -o "$work/$name-stratmesh.ply" -q
    times+=("$(echo "$(now) - $start" | bc -l)")
  done
  peer_line=$("$peer" "$cloud" -o "$work/$name-afr.ply")
  printf '%s\n' "${times[@]}" | sort -g > "$work/times"
  median=$(sed -n "$(( (runs + 1) / 2 ))p" "$work/times")
  fastest=$(head -n 1 "$work/times")
  peer_seconds=$(printf '%s' "$peer_line" | sed 's/.*"seconds": \([0-9.e+-]*\).*/\1/')
  points=$(printf '%s' "$peer_line" | sed 's/.*"points": \([0-9]*\).*/\1/')
  printf '{"cloud": "%s", "points": %s, "runs": %s, "tool_seconds": %.4f, "tool_min_seconds": %.4f, "peer_seconds": %.3f, "ratio": %.1f}\n' \
    "$name" "$points" "$runs" "$median" "$fastest" "$peer_seconds" \
    "$(echo "$peer_seconds / $median" | bc -l)"
done
