#!/usr/bin/env bash
# CI stage: cross-architecture determinism and the bare-metal build.
#   1. tests/digest built natively, and statically for aarch64 and 32-bit ARM (hard-float),
#      the ARM builds run under qemu-user: the three digests must be identical, and the
#      digest of the full-build features (armhf is built with STRATMESH_SMALL_CODE) the same
#      on x86-64 and aarch64.
#   2. examples/firmware built for a Cortex-M7 (newlib-nano, no heap/exceptions/RTTI):
#      image size, the library's own size (at most 32 KiB), no heap or exception symbols;
#      the same program built and run on the host as a smoke test.
#   3. the worst-case stack depth of reconstruct and delaunay_2d on the Cortex-M7, from
#      GCC's per-function stack usage and call graph (at most 16 KiB).
# Needs root for apt-get (run after `apt-get update`); installs only what is missing.
set -euo pipefail
cd "$(dirname "$0")/.."
export DEBIAN_FRONTEND=noninteractive
out=build-arm
mkdir -p "$out"
step() { printf '\n==== arm: %s (%ss)\n' "$1" "$SECONDS"; }

step "install cross compilers and qemu-user"
need=()
for p in gcc-arm-none-eabi libnewlib-arm-none-eabi libstdc++-arm-none-eabi-newlib \
         g++-arm-linux-gnueabihf g++-aarch64-linux-gnu qemu-user python3; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || need+=("$p")
done
if [ ${#need[@]} -gt 0 ]; then
  apt-get install -y -q --no-install-recommends "${need[@]}"
fi

step "digest: native, aarch64 and armhf (small code) under qemu"
warn=(-Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wsign-conversion -Wdouble-promotion -Werror)
src=(tests/digest/digest.cpp stratmesh.cpp)
g++ -std=c++17 -O2 "${warn[@]}" -I. -Itests "${src[@]}" -o "$out/digest-native"
# -Wno-psabi (both ARM builds): GCC notes that passing std::pair<double, double> changed
# in GCC 10.1 (an ABI remark about shapes.h, not a defect).
aarch64-linux-gnu-g++ -std=c++17 -O2 "${warn[@]}" -Wno-psabi -static -I. -Itests "${src[@]}" -o "$out/digest-aarch64"
# armhf is built as the firmware builds the library (STRATMESH_SMALL_CODE), so the digest
# also shows that leaving out the faster paths changes no byte.
arm-linux-gnueabihf-g++ -std=c++17 -O2 "${warn[@]}" -Wno-psabi -static -DSTRATMESH_SMALL_CODE -I. -Itests "${src[@]}" -o "$out/digest-armhf"
"$out/digest-native" > "$out/digest-native.txt"
# The control: a call that does not return ok fails the digest.
if "$out/digest-native" --control-bad-status > "$out/digest-control.txt"; then
  echo "FAIL: the digest passes a call that did not return ok"; exit 1
fi
echo "the digest fails on a status that is not ok (control): ok"
qemu-aarch64 "$out/digest-aarch64" > "$out/digest-aarch64.txt"
qemu-arm "$out/digest-armhf" > "$out/digest-armhf.txt"
cat "$out/digest-native.txt"
for a in native aarch64 armhf; do
  printf '%-8s %s   (%s)\n' "$a" "$(grep '^digest ' "$out/digest-$a.txt" | cut -d' ' -f2)" \
    "$(grep '^input ' "$out/digest-$a.txt")"
done
n=$(grep -h '^digest ' "$out"/digest-{native,aarch64,armhf}.txt | sort -u | wc -l)
if [ "$n" != 1 ]; then
  diff "$out/digest-native.txt" "$out/digest-aarch64.txt" || true
  diff "$out/digest-native.txt" "$out/digest-armhf.txt" || true
  echo "FAIL: the digests differ between architectures"; exit 1
fi
echo "all three digests are identical"
# What STRATMESH_SMALL_CODE leaves out (closed ends, crescents, caps, drop_outliers,
# cap_ends, surface flips, the local put-back of peeled triangles) has its own digest, from
# the two builds without the macro.
for a in native aarch64; do
  printf '%-8s full %s\n' "$a" "$(grep '^full ' "$out/digest-$a.txt" | cut -c8-)"
done
n=$(grep -h '^full ' "$out"/digest-{native,aarch64}.txt | sort -u | wc -l)
if [ "$n" != 1 ] || grep -q 'not built' "$out/digest-native.txt"; then
  echo "FAIL: the full-build digests differ between x86-64 and aarch64"; exit 1
fi
echo "the full-build digests are identical"

step "firmware: Cortex-M7 image, library size, no heap or exceptions"
bash examples/firmware/build.sh "$out/firmware"
g++ -std=c++17 -O2 "${warn[@]}" -fno-exceptions -fno-rtti -I. -Iexamples/firmware \
  examples/firmware/main.cpp examples/firmware/cloud_data.cpp stratmesh.cpp -o "$out/firmware-host"
"$out/firmware-host" || { echo "FAIL: the firmware program, run on the host, returned $?"; exit 1; }
echo "the firmware program reconstructs its cloud (run on the host): ok"
# The same program for 32-bit ARM (hard-float, 32-bit size_t like the M7), under qemu.
arm-linux-gnueabihf-g++ -std=c++17 -O2 "${warn[@]}" -Wno-psabi -fno-exceptions -fno-rtti -static \
  -I. -Iexamples/firmware examples/firmware/main.cpp examples/firmware/cloud_data.cpp stratmesh.cpp \
  -o "$out/firmware-armhf"
qemu-arm "$out/firmware-armhf" || { echo "FAIL: the firmware program, under qemu-arm, returned $?"; exit 1; }
echo "the firmware program reconstructs its cloud (32-bit ARM, qemu-arm): ok"

step "stack: worst-case depth on the Cortex-M7 from -fstack-usage and the call graph"
arm-none-eabi-g++ -mcpu=cortex-m7 -mfpu=fpv5-d16 -mfloat-abi=hard -mthumb -Os -std=c++17 \
  -fno-exceptions -fno-rtti -DSTRATMESH_SMALL_CODE -fcallgraph-info=su -I. -c stratmesh.cpp -o "$out/stack_m7.o" \
  -dumpdir "$out/"
python3 examples/firmware/stack_bound.py --limit 16384 "$out"/*stack_m7*.ci
# The control: a call graph without the entry points must fail, not pass unchecked.
printf 'graph: { title: "none"\nnode: { title: "f" label: "f\\n8 bytes (static)" }\n}\n' \
  > "$out/no_entry_points.ci"
if python3 examples/firmware/stack_bound.py --limit 16384 "$out/no_entry_points.ci" >/dev/null; then
  echo "FAIL: stack_bound.py passes a call graph without entry points"; exit 1
fi
echo "stack_bound.py fails on a call graph without entry points (control): ok"

step "arm done"
