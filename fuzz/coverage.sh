#!/usr/bin/env bash
# Line coverage of stratmesh.h reached by the fuzz corpora alone: builds the replay
# drivers (fuzz/replay) with clang's source-based coverage in build-coverage, runs each on
# its corpus (fuzz/corpus/<harness>, or CORPUS_ROOT/<harness> if set), and prints
# llvm-cov's report for the header plus one summary line. With --tests, the doctest
# suites run too and the report covers corpora and tests together.
# Needs clang++, llvm-profdata and llvm-cov (Debian: clang-14, llvm-14) and doctest.
set -euo pipefail
cd "$(dirname "$0")/.."

with_tests=0
[ "${1:-}" = "--tests" ] && with_tests=1
build=build-coverage
corpus_root=${CORPUS_ROOT:-fuzz/corpus}
profdata=$(command -v llvm-profdata || command -v llvm-profdata-14)
cov=$(command -v llvm-cov || command -v llvm-cov-14)
jobs=$(nproc 2>/dev/null || echo 2)

cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_COMPILER=clang++ \
  -DSTRATMESH_BUILD_TESTS=ON -DSTRATMESH_BUILD_EXAMPLES=ON -DSTRATMESH_INSTALL=OFF \
  -DCMAKE_CXX_FLAGS="-fprofile-instr-generate -fcoverage-mapping" >/dev/null
harnesses=(fuzz_predicates fuzz_delaunay fuzz_reconstruct fuzz_stream fuzz_join fuzz_cloud_reader)
targets=()
for h in "${harnesses[@]}"; do targets+=("fuzz_replay_$h"); done
[ "$with_tests" = 1 ] && targets+=(stratmesh_tests)
cmake --build "$build" -j"$jobs" --target "${targets[@]}" >/dev/null

rm -rf "$build/profiles"
mkdir -p "$build/profiles"
objects=()
for h in "${harnesses[@]}"; do
  LLVM_PROFILE_FILE="$build/profiles/$h.profraw" STRATMESH_FUZZ_STRICT=0 \
    "$build/tests/fuzz-replay/fuzz_replay_$h" "$corpus_root/$h" 2>/dev/null
  objects+=(-object "$build/tests/fuzz-replay/fuzz_replay_$h")
  printf '%s: %s inputs\n' "$h" "$(find "$corpus_root/$h" -type f | wc -l)"
done
if [ "$with_tests" = 1 ]; then
  LLVM_PROFILE_FILE="$build/profiles/tests.profraw" "$build/tests/stratmesh_tests" >/dev/null
  objects+=(-object "$build/tests/stratmesh_tests")
fi
"$profdata" merge -sparse "$build"/profiles/*.profraw -o "$build/profiles/all.profdata"
# The first object goes without -object.
"$cov" report "${objects[@]:1}" -instr-profile="$build/profiles/all.profdata" stratmesh.h \
  | tee "$build/coverage.txt"
awk '/^TOTAL|stratmesh.h/ {line=$0} END {n=split(line, f); print "stratmesh.h line coverage: " f[n-3] " of lines (" f[n-5] " lines, " f[n-4] " missed)"}' \
  "$build/coverage.txt"
