#!/usr/bin/env bash
# Builds the firmware example for a Cortex-M7 (hard-float, double-precision FPU) with
# newlib-nano; no heap, no exceptions, no RTTI. Links with nosys.specs (newlib's crt0,
# default memory layout, syscall stubs): enough to link and size the image; a board port
# replaces that with its own startup file and linker script.
#   examples/firmware/build.sh [output directory]   (default: build-firmware)
# Prints the image's size, the library's own size for the M7, and fails if the library
# code is above 32 KiB of .text or references the heap or exceptions.
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
out="${1:-$root/build-firmware}"
mkdir -p "$out"
cxx=arm-none-eabi-g++
# Code size comes first here: STRATMESH_SMALL_CODE leaves out what only makes the
# reconstruction faster (parallel layers, which a single core cannot use, and the safety
# net's shortcut; see the header's configuration macros). The full library's size is
# printed too.
flags=(-mcpu=cortex-m7 -mfpu=fpv5-d16 -mfloat-abi=hard -mthumb -Os -std=c++17
       -fno-exceptions -fno-rtti -DSTRATMESH_SMALL_CODE
       -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wsign-conversion -Wdouble-promotion -Werror)

# The library alone, as its own object.
"$cxx" "${flags[@]}" -I"$root" -c "$root/stratmesh.cpp" -o "$out/stratmesh_m7.o"
# The image: gc-sections drops whatever main does not reach.
"$cxx" "${flags[@]}" -ffunction-sections -fdata-sections -I"$root" -I"$root/examples/firmware" \
  "$root/examples/firmware/main.cpp" "$root/examples/firmware/cloud_data.cpp" "$root/stratmesh.cpp" \
  --specs=nano.specs --specs=nosys.specs -Wl,--gc-sections -Wl,-Map="$out/firmware.map" \
  -o "$out/firmware.elf"

echo "== the image (arm-none-eabi-size)"
arm-none-eabi-size "$out/firmware.elf"
echo "== the library alone for the Cortex-M7, -Os (arm-none-eabi-size)"
arm-none-eabi-size "$out/stratmesh_m7.o"
section_bytes() {  # object, section name pattern
  arm-none-eabi-size -A "$1" | awk -v pattern="$2" '$1 ~ pattern {s += $2} END {print s + 0}'
}
code=$(section_bytes "$out/stratmesh_m7.o" '^\.text')
ro=$(section_bytes "$out/stratmesh_m7.o" '^\.rodata')
echo "library .text: $code bytes (limit 32768), .rodata: $ro bytes (strings and tables)"
[ "$code" -le 32768 ] || { echo "FAIL: the library's code is above 32 KiB on the Cortex-M7"; exit 1; }
full=()
for flag in "${flags[@]}"; do [ "$flag" = -DSTRATMESH_SMALL_CODE ] || full+=("$flag"); done
"$cxx" "${full[@]}" -I"$root" -c "$root/stratmesh.cpp" -o "$out/stratmesh_m7_full.o"
echo "without STRATMESH_SMALL_CODE (parallel layers, the net's shortcut): .text $(section_bytes "$out/stratmesh_m7_full.o" '^\.text') bytes"

echo "== symbols the library needs from outside (arm-none-eabi-nm -u)"
arm-none-eabi-nm -u "$out/stratmesh_m7.o" | tr -s ' ' | sed 's/^ //'
forbidden='^(malloc|calloc|realloc|free|_malloc_r|_free_r|_Zn[wa][jm].*|_Zd[la]Pv.*|__cxa_throw|__cxa_allocate_exception|__cxa_begin_catch|__gxx_personality_v0|_Unwind_.*)$'
if arm-none-eabi-nm -u "$out/stratmesh_m7.o" | awk '{print $NF}' | grep -E "$forbidden"; then
  echo "FAIL: the library references the heap or exceptions"; exit 1
fi
echo "the library references no heap or exception function"
echo "== heap and exception symbols in the linked image (from newlib's startup, not the library)"
arm-none-eabi-nm "$out/firmware.elf" | awk '{print $NF}' \
  | grep -E '^(malloc|free|_malloc_r|_free_r|_sbrk|_sbrk_r|atexit|__cxa_atexit|_Znwj|_Znwm|__cxa_throw|__cxa_allocate_exception)$' \
  | sed 's/^/  defined: /' || echo "  none"
if arm-none-eabi-nm "$out/firmware.elf" | awk '{print $NF}' | grep -qE '^(malloc|_malloc_r|_Znwj|_Znwm|__cxa_throw|__cxa_allocate_exception)$'; then
  echo "FAIL: the image contains an allocator or exception machinery"; exit 1
fi
