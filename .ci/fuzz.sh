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

# libFuzzer saves a unit that took longer than -report_slow_units seconds of wall time. On
# a shared VM a stall of the host can make any unit look slow (CI saw an 11 s unit once, a
# 51-byte input; the same seed and corpus here never went above 1 s in 28k runs), so each
# one is replayed three times: it stays a failure if even its fastest replay takes
# slow_replay_ms or more, far above any harness's normal worst (tens of milliseconds);
# otherwise it is reported with its bytes and set aside.
slow_replay_ms=2000
confirm_slow_units() {
  local harness=$1 artifacts=$2 f fastest k start ms
  for f in "$artifacts"/slow-unit-*; do
    [ -f "$f" ] || continue
    fastest=
    for k in 1 2 3; do
      start=$(date +%s%N)
      "$build/fuzz/$harness" "$f" >/dev/null 2>&1 || { fastest=failed; break; }
      ms=$(( ($(date +%s%N) - start) / 1000000 ))
      if [ -z "$fastest" ] || [ "$ms" -lt "$fastest" ]; then fastest=$ms; fi
    done
    printf '%s: %s base64: %s\n' "$harness" "$(basename "$f")" "$(base64 -w0 "$f" | head -c 8192)"
    if [ "$fastest" != failed ] && [ "$fastest" -lt "$slow_replay_ms" ]; then
      echo "  replayed in $fastest ms at best: a stall of the machine, not a slow path; set aside"
      mkdir -p "$artifacts/../stalls"
      mv "$f" "$artifacts/../stalls/"
    else
      echo "  replay: $fastest ms at best: a slow path"
    fi
  done
}

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
    -report_slow_units=10 -rss_limit_mb=1024 -malloc_limit_mb=64 -max_len=65536 -print_final_stats=1 \
    -artifact_prefix="$work/artifacts/" >"$work/log" 2>&1 || rc=$?
  tail -n 30 "$work/log"
  confirm_slow_units "$harness" "$work/artifacts"
  if [ "$rc" != 0 ] || ls "$work/artifacts"/* >/dev/null 2>&1; then
    echo "$harness FAILED (exit $rc); log: $work/log; reproducers:"; ls -l "$work/artifacts"
    for f in "$work/artifacts"/*; do
      [ -f "$f" ] && printf '%s base64: %s\n' "$(basename "$f")" "$(head -c 4096 "$f" | base64 -w0)"
    done
    status=1
  fi
done
exit $status
