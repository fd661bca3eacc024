#!/usr/bin/env bash
# CI fuzz stage: builds the libFuzzer harnesses (clang, ASan + UBSan) in build-fuzz and
# runs each for about FUZZ_SECONDS (default 45) on a copy of its seed corpus. Exits
# non-zero on any crash, sanitizer report, broken invariant, leak, timeout or memory limit.
# Installs nothing: needs clang++ and libFuzzer (Debian: clang-14, libclang-rt-14-dev).
set -euo pipefail
cd "$(dirname "$0")/.."

seconds=${FUZZ_SECONDS:-45}
cxx=${FUZZ_CXX:-clang++}
build=build-fuzz
jobs=$(nproc 2>/dev/null || echo 2)

cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER="$cxx" \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -gline-tables-only -DNDEBUG" \
  -DSTRATMESH_BUILD_FUZZ=ON -DSTRATMESH_BUILD_TESTS=OFF -DSTRATMESH_BUILD_EXAMPLES=ON \
  -DSTRATMESH_INSTALL=OFF -DSTRATMESH_WERROR=ON \
  -DCMAKE_CXX_FLAGS="-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer"
cmake --build "$build" -j"$jobs" --target fuzz_predicates fuzz_delaunay fuzz_reconstruct fuzz_stream fuzz_join fuzz_cloud_reader

export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:allocator_may_return_null=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}

# libFuzzer saves a unit that took longer than -report_slow_units seconds of wall time
# (slow-unit-*) and stops on one that took longer than -timeout (timeout-*, exit code 70).
# On a shared VM a stall of the host can make any unit look slow: CI saw an 11 s unit once,
# a 51-byte fuzz_delaunay input, where the same seed and corpus here never took 1 s in 28k
# runs, nor any unit in 250k more. So each such unit is replayed three times (at most 60 s
# each): it stays a failure if even its fastest replay takes slow_replay_ms or more, far
# above any harness's normal worst (tens of milliseconds), or fails; otherwise it is set
# aside as a stall, with its bytes printed. A run that stopped on a timeout whose unit
# replays fast passes, and says so.
slow_replay_ms=2000
set_aside_stalls() {
  local harness=$1 artifacts=$2 f fastest k start ms
  for f in "$artifacts"/slow-unit-* "$artifacts"/timeout-*; do
    [ -f "$f" ] || continue
    fastest=
    for k in 1 2 3; do
      start=$(date +%s%N)
      timeout 60 "$build/fuzz/$harness" "$f" >/dev/null 2>&1 || { fastest=failed; break; }
      ms=$(( ($(date +%s%N) - start) / 1000000 ))
      if [ -z "$fastest" ] || [ "$ms" -lt "$fastest" ]; then fastest=$ms; fi
    done
    if [ "$fastest" != failed ] && [ "$fastest" -lt "$slow_replay_ms" ]; then
      printf '%s: %s replayed in %s ms at best: a stall, set aside; base64: %s\n' "$harness" \
        "$(basename "$f")" "$fastest" "$(head -c 4096 "$f" | base64 -w0)"
      mkdir -p "$artifacts/../stalls"
      mv "$f" "$artifacts/../stalls/"
    else
      printf '%s: %s replay: %s ms at best\n' "$harness" "$(basename "$f")" "$fastest"
    fi
  done
}

status=0
summary=()
for harness in fuzz_predicates fuzz_delaunay fuzz_reconstruct fuzz_stream fuzz_join fuzz_cloud_reader; do
  work="$build/run/$harness"
  rm -rf "$work"
  mkdir -p "$work/corpus" "$work/artifacts"
  cp fuzz/corpus/"$harness"/* "$work/corpus/"
  printf '\n==== %s: %ss\n' "$harness" "$seconds"
  # malloc_limit_mb: no single allocation above 64 MB (a reader reserving for a lying
  # header fails here); rss_limit_mb: the whole process under 1 GB. A fixed seed makes a
  # run repeatable (FUZZ_SEED=0 asks libFuzzer for a fresh one).
  # fuzz_reconstruct runs without the entropic schedule: its bookkeeping, per coverage
  # counter of every run, took a quarter of that harness's time (a run touches thousands of
  # the library's counters), and 60 s without it reach as many edges.
  schedule=()
  [ "$harness" = fuzz_reconstruct ] && schedule=(-entropic=0)
  rc=0
  "$build/fuzz/$harness" "$work/corpus" -seed="${FUZZ_SEED:-1}" -max_total_time="$seconds" -timeout=25 \
    -report_slow_units=10 -rss_limit_mb=1024 -malloc_limit_mb=64 -max_len=65536 -print_final_stats=1 \
    "${schedule[@]}" -artifact_prefix="$work/artifacts/" >"$work/log" 2>&1 || rc=$?
  tail -n 30 "$work/log"
  # Executions per second: libFuzzer's final stats (-print_final_stats=1).
  units=$(sed -n 's/^stat::number_of_executed_units: *//p' "$work/log" | tail -n 1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$work/log" | tail -n 1)
  printf '%s: %s executions in about %ss, %s per second\n' "$harness" "${units:-?}" "$seconds" "${rate:-?}"
  summary+=("$(printf '%-18s %8s exec/s' "$harness" "${rate:-?}")")
  set_aside_stalls "$harness" "$work/artifacts"
  if [ "$rc" = 70 ] && ls "$work/stalls"/timeout-* >/dev/null 2>&1 &&
     ! ls "$work/artifacts"/* >/dev/null 2>&1; then
    echo "$harness stopped early on a timeout that replays fast (a stall); not a failure"
    rc=0
  fi
  if [ "$rc" != 0 ] || ls "$work/artifacts"/* >/dev/null 2>&1; then
    echo "$harness FAILED (exit $rc); log: $work/log; reproducers:"; ls -l "$work/artifacts"
    for f in "$work/artifacts"/*; do
      [ -f "$f" ] && printf '%s base64: %s\n' "$(basename "$f")" "$(head -c 4096 "$f" | base64 -w0)"
    done
    status=1
  fi
done
printf '\n==== executions per second (%ss each)\n' "$seconds"
printf '%s\n' "${summary[@]}"
exit $status
