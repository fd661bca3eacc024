#!/usr/bin/env bash
# cli_io_bench.sh - the stratmesh tool's reading and writing times on a 1e6-point cloud.
#
#   bench/cli_io_bench.sh [--runs N] [--work DIR] [--stratmesh PATH] [--quick]
#
# Makes a bumpy tube of 1,000,000 points (binary little-endian PLY of float x, y, z, 12 MB)
# in DIR (default /tmp/stratmesh_cli_io_bench), and the same points as ascii PLY and as XYZ
# columns. Then runs the tool N times (default 5) per case with --report and prints the
# median (and the least) of the report's seconds.read (inputs) and seconds.write (outputs),
# and of the wall time of the default command, `stratmesh tube1e6.ply -o out.ply`.
# --quick: binary PLY in and out only. The outputs are written to DIR as new files (removed
# before each run), so the write times include the flush to the disk there.
#
# Tools, unless given: the tool at build/examples/cli/stratmesh (relative to the source
# tree; STRATMESH works too), and a python3 with numpy (PYTHON, else python3 or
# /usr/bin/python3, whichever imports numpy). Exit status: 0 measured, 1 a run failed, 2
# usage error.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
stratmesh=${STRATMESH:-$root/build/examples/cli/stratmesh}
work=/tmp/stratmesh_cli_io_bench
runs=5
quick=0

usage() {
  sed -n '4p' "$0" | sed 's/^# \{0,1\}//' >&2
  exit "${1:-2}"
}

while [ $# -gt 0 ]; do
  case "$1" in
    --runs) [ $# -ge 2 ] || usage; runs=$2; shift 2 ;;
    --work) [ $# -ge 2 ] || usage; work=$2; shift 2 ;;
    --stratmesh) [ $# -ge 2 ] || usage; stratmesh=$2; shift 2 ;;
    --quick) quick=1; shift ;;
    -h|--help) usage 0 ;;
    *) usage ;;
  esac
done
case "$runs" in ''|*[!0-9]*|0) usage ;; esac
[ -x "$stratmesh" ] || { echo "cli_io_bench: no tool at $stratmesh (build it first)" >&2; exit 2; }

python=""
for candidate in ${PYTHON:-} python3 /usr/bin/python3; do
  if "$candidate" -c 'import numpy' 2>/dev/null; then python=$candidate; break; fi
done
[ -n "$python" ] || { echo "cli_io_bench: needs a python3 with numpy (set PYTHON)" >&2; exit 2; }

mkdir -p "$work"
cloud=$work/tube1e6.ply
out=$work/out
if [ ! -s "$cloud" ] || [ ! -s "$work/tube1e6_ascii.ply" ] || [ ! -s "$work/tube1e6.xyz" ]; then
  "$python" - "$work" <<'EOF'
import math, sys
import numpy as np
work = sys.argv[1]
n = 1000000
rng = np.random.default_rng(1)
t = 2 * math.pi * rng.random(n)
z = 8 * rng.random(n)
r = 1 + 0.25 * np.sin(5 * t) * np.cos(z)
xyz = np.stack([r * np.cos(t), r * np.sin(t), z], 1).astype('<f4')
header = ("ply\nformat {} 1.0\nelement vertex %d\nproperty float x\nproperty float y\n"
          "property float z\nend_header\n" % n)
with open(work + '/tube1e6.ply', 'wb') as f:
    f.write(header.format('binary_little_endian').encode() + xyz.tobytes())
# Nine significant digits: every float reads back exactly.
with open(work + '/tube1e6_ascii.ply', 'w') as f:
    f.write(header.format('ascii'))
    np.savetxt(f, xyz, fmt='%.9g')
with open(work + '/tube1e6.xyz', 'w') as f:
    np.savetxt(f, xyz, fmt='%.9g')
EOF
fi

# One timed run: prints "READ WRITE WALL" seconds; fails with the tool's messages.
run_once() {
  local start end
  # A new output each time: replacing a file also frees the old one's blocks, a cost of
  # the file system, not of the writing.
  rm -f "$out".*
  start=$(date +%s%N)
  if ! "$stratmesh" "$@" --report "$work/report.json" -q 2>"$work/stderr.txt"; then
    echo "cli_io_bench: failed: stratmesh $*" >&2
    cat "$work/stderr.txt" >&2
    return 1
  fi
  end=$(date +%s%N)
  "$python" -c 'import json, sys
s = json.load(open(sys.argv[1]))["seconds"]
print(s["read"], s["write"], (int(sys.argv[3]) - int(sys.argv[2])) / 1e9)' \
    "$work/report.json" "$start" "$end"
}

# The median and the least of the numbers on standard input.
summary() {
  sort -g | awk '{ v[NR] = $1 } END {
    m = (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2
    printf "%8.4f s  (least %.4f s)\n", m, v[1] }'
}

# measure "LABEL:COLUMN"... -- ARGS...: runs the tool N times with ARGS and prints, for each
# label, the median of that column (1 read, 2 write, 3 wall time).
measure() {
  local labels=()
  while [ "$1" != "--" ]; do labels+=("$1"); shift; done
  shift
  local lines=""
  for ((i = 0; i < runs; ++i)); do
    lines+="$(run_once "$@")"$'\n' || exit 1
  done
  local label
  for label in "${labels[@]}"; do
    printf '%-46s %s\n' "${label%:*}" "$(printf '%s' "$lines" | cut -d' ' -f"${label##*:}" | summary)"
  done
}

echo "stratmesh $("$stratmesh" --version | cut -d' ' -f2), median of $runs runs, files in $work"
# Read once untimed so that every case reads from the page cache.
cat "$cloud" "$work/tube1e6_ascii.ply" "$work/tube1e6.xyz" >/dev/null
measure "read binary PLY (12 MB):1" "write binary PLY:2" \
  "end to end: stratmesh tube1e6.ply -o out.ply:3" -- "$cloud" -o "$out.ply"
if [ "$quick" = 0 ]; then
  mb() { echo $(($(stat -c %s "$1") / 1000000)); }
  measure "read ascii PLY ($(mb "$work/tube1e6_ascii.ply") MB):1" -- "$work/tube1e6_ascii.ply" \
    -o "$out.ply"
  measure "read XYZ ($(mb "$work/tube1e6.xyz") MB):1" -- "$work/tube1e6.xyz" -o "$out.ply"
  measure "write ascii PLY:2" -- "$cloud" -o "$out.ply" --ascii
  measure "write OBJ:2" -- "$cloud" -o "$out.obj"
  measure "write OFF:2" -- "$cloud" -o "$out.off"
  measure "write binary STL:2" -- "$cloud" -o "$out.stl"
  measure "write ascii STL:2" -- "$cloud" -o "$out.stl" --ascii
fi
rm -f "$out".* "$work/report.json" "$work/stderr.txt"
