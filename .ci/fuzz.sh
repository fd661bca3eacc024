#!/usr/bin/env bash
# CI fuzz stage: builds the libFuzzer harnesses (clang, ASan + UBSan) in build-fuzz and
# runs each for about FUZZ_SECONDS (default 60) on a copy of its seed corpus. Exits
# non-zero on any crash, sanitizer report, broken invariant, leak, timeout or memory limit.
# Installs nothing: needs clang++ and libFuzzer (Debian: clang-14, libclang-rt-14-dev).
set -euo pipefail
cd "$(dirname "$0")/.."

seconds=${FUZZ_SECONDS:-60}
cxx=${FUZZ_CXX:-clang++}
build=build-fuzz
jobs=$(nproc 2>/dev/null || echo 2)

cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER="$cxx" \
  -DSTRATMESH_BUILD_FUZZ=ON -DSTRATMESH_BUILD_TESTS=OFF -DSTRATMESH_BUILD_EXAMPLES=ON \
  -DSTRATMESH_INSTALL=OFF -DSTRATMESH_WERROR=ON \
  -DCMAKE_CXX_FLAGS="-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer"
cmake --build "$build" -j"$jobs" --target fuzz_predicates fuzz_delaunay fuzz_reconstruct fuzz_stream fuzz_cloud_reader

export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:allocator_may_return_null=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}

status=0
for harness in fuzz_predicates fuzz_delaunay fuzz_reconstruct fuzz_stream fuzz_cloud_reader; do
  work="$build/run/$harness"
  rm -rf "$work"
  mkdir -p "$work/corpus" "$work/artifacts"
  cp fuzz/corpus/"$harness"/* "$work/corpus/"
  printf '\n==== %s: %ss\n' "$harness" "$seconds"
  # malloc_limit_mb: no single allocation above 64 MB (a reader reserving for a lying
  # header fails here); rss_limit_mb: the whole process under 1 GB. A fixed seed makes a
  # run repeatable (FUZZ_SEED=0 asks libFuzzer for a fresh one).
  rc=0
  "$build/fuzz/$harness" "$work/corpus" -seed="${FUZZ_SEED:-1}" -max_total_time="$seconds" -timeout=25 \
    -rss_limit_mb=1024 -malloc_limit_mb=64 -max_len=65536 -print_final_stats=1 \
    -artifact_prefix="$work/artifacts/" >"$work/log" 2>&1 || rc=$?
  tail -n 30 "$work/log"
  if [ "$rc" != 0 ] || ls "$work/artifacts"/* >/dev/null 2>&1; then
    echo "$harness FAILED (exit $rc); log: $work/log; reproducers:"; ls -l "$work/artifacts"
    status=1
  fi
done
exit $status
