#!/usr/bin/env bash
# The library's suites for another architecture, built statically with the cross compiler
# and its default flags, run under qemu-user. Usage: .ci/emulated.sh CXX QEMU BUILD_DIR
# (for example arm-linux-gnueabihf-g++ qemu-arm build-arm).
# The sources compile one per core, and the cases run in two halves at once (a random order
# with a fixed seed, so that each half gets a share of the long cases): emulation is the
# slowest stage of CI.
set -euo pipefail
cd "$(dirname "$0")/.."
cxx=$1 qemu=$2 build=$3
jobs=$(nproc 2>/dev/null || echo 2)
mkdir -p "$build/suite"
suites=(tests/test_main.cpp tests/test_status.cpp tests/test_predicates.cpp
        tests/test_delaunay.cpp tests/test_reconstruct.cpp tests/test_stream.cpp
        tests/test_parallel.cpp tests/test_parting.cpp tests/test_join.cpp tests/test_c_api.cpp
        stratmesh.cpp)
printf '%s\n' "${suites[@]}" | xargs -P "$jobs" -I{} sh -c \
  '"$0" -std=gnu++17 -O2 -Wno-psabi -I. -Itests -c "$2" -o "$1/suite/$(basename "$2" .cpp).o"' \
  "$cxx" "$build" {}
"$cxx" -static -pthread "$build"/suite/*.o -o "$build/stratmesh_tests"

# Under emulation the suites run without their longest cases, which compare two code paths
# of one build (jobs and order, stream and batch, flips) on every test shape or a million
# points, mesh each shape in every pose (the shapes' other cases stay), or check the tests'
# own checkers. The digests of .ci/arm.sh compare the architectures' meshes, the
# stream's and the flips' included, and x86-64 runs every case.
skip='parallel layers:*,one million uniform points,stream:*,surface_flips:*,drop_outliers: stray*,reconstruction with several layers*,cap_ends: the stream*,find_parting: no tube*,reconstruction of *every pose*,checker:*'
order=(--order-by=rand --rand-seed=7 --test-case-exclude="$skip")
count=$("$qemu" "$build/stratmesh_tests" --count "${order[@]}" | sed -n 's/.*passing the current filters: *//p')
[ "${count:-0}" -gt 0 ] || { echo "no test case to run under $qemu"; exit 1; }
half=$(( (count + 1) / 2 ))
"$qemu" "$build/stratmesh_tests" "${order[@]}" --first=1 --last="$half" >"$build/half1.log" 2>&1 & first=$!
"$qemu" "$build/stratmesh_tests" "${order[@]}" --first=$((half + 1)) --last="$count" >"$build/half2.log" 2>&1 & second=$!
status=0
wait "$first" || status=1
wait "$second" || status=1
for log in "$build/half1.log" "$build/half2.log"; do
  if [ "$status" = 0 ]; then tail -n 4 "$log"; else cat "$log"; fi
done
echo "$qemu: $count test cases in two halves"
exit $status
