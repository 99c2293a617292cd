#!/bin/bash -eu
# The OSS-Fuzz / ClusterFuzzLite build contract: compile with $CC/$CXX and
# $CFLAGS/$CXXFLAGS (they carry the sanitizer), link the engine with
# $LIB_FUZZING_ENGINE, leave the fuzzers in $OUT ($WORK for scratch).
# ci/fuzz runs this same script with Debian's clang to keep it working.
#
# Fuzzers left in $OUT:
#   fuzz_elf, fuzz_board, fuzz_scenario, fuzz_golden, fuzz_vcd, fuzz_fwconfig  the bench's parsers
#   fuzz_firmware_<name>  a firmware of this repository on its board: G-code
#     into its serial port (bench/fuzz/FirmwareTarget.hpp), configured by
#     fuzz_firmware_<name>.avrbench beside it; the ELF and boards under
#     $OUT/avrbench/; a seed corpus of the family's lines
set -euo pipefail  # also when run as `bash build.sh`, which ignores the #! flags
cd "$(dirname "$0")/.."
src="$PWD"
work="${WORK:-/tmp/avrbench-work}"
mkdir -p "$work" "$OUT"

# The firmware: the repository's own AVR build (avr-gcc), only what is fuzzed;
# the contract's host flags (sanitizers) are not for avr-gcc.
firmware=(printer3d_interp printer3d_interp_thesis_parser grbl_stepper delta delta_thesis)
env -u CFLAGS -u CXXFLAGS -u LDFLAGS cmake -S firmware -B "$work/firmware" -DCMAKE_TOOLCHAIN_FILE="$src/cmake/avr-gcc.cmake" \
  -DCMAKE_BUILD_TYPE=MinSizeRel -DSIMAVR_INCLUDE_DIR=/usr/include/simavr > "$work/firmware.log"
env -u CFLAGS -u CXXFLAGS -u LDFLAGS \
  cmake --build "$work/firmware" -j"$(nproc)" --target "${firmware[@]}" >> "$work/firmware.log"

# The host side with the contract's compiler, flags and engine.
cmake -S . -B "$work/build" -DAVRBENCH_FUZZ=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_UNITY_BUILD=ON \
  -DCMAKE_C_COMPILER="$CC" -DCMAKE_CXX_COMPILER="$CXX" \
  -DAVRBENCH_LIB_FUZZING_ENGINE="$LIB_FUZZING_ENGINE" > "$work/build.log"
cmake --build "$work/build" -j"$(nproc)" \
  --target fuzz_elf fuzz_board fuzz_scenario fuzz_golden fuzz_vcd fuzz_fwconfig fuzz_firmware >> "$work/build.log"
for parser in elf board scenario golden vcd fwconfig; do
  cp "$work/build/fuzz/fuzz_$parser" "$OUT/"
done

data="$OUT/avrbench"
mkdir -p "$data/boards"
cp bench/boards/*.yaml tests/fixtures/fuzz/firmware/*.yaml "$data/boards/"
# fuzz_firmware_<name> <elf> <board> <seed lines...>
firmware_fuzzer() {
  local name="$1" elf="$2" board="$3"
  shift 3
  cp "$work/firmware/$elf.elf" "$data/"
  cp "$work/build/fuzz/fuzz_firmware" "$OUT/fuzz_firmware_$name"
  cat > "$OUT/fuzz_firmware_$name.avrbench" <<CONFIG
AVRBENCH_FUZZ_ELF=\$ORIGIN/avrbench/$elf.elf
AVRBENCH_FUZZ_BOARD=\$ORIGIN/avrbench/boards/$board.yaml
AVRBENCH_BOARDS_DIR=\$ORIGIN/avrbench/boards
CONFIG
  local seeds="$work/seeds-$name" i=0
  rm -rf "$seeds" && mkdir -p "$seeds"
  for line in "$@"; do
    printf '%s\n' "$line" > "$seeds/seed-$i"
    i=$((i + 1))
  done
  (cd "$seeds" && python3 -m zipfile -c "$OUT/fuzz_firmware_${name}_seed_corpus.zip" seed-*)
}
# Seed lines as `avrbench fuzz` starts from (bench/tools/FuzzCommand.cpp);
# the delta's from the thesis program's own targets (docs/FUZZING.md).
marlin=("G1 X1 Y1 F500" "G01 X0.5 Y0 F10" "M105" "M114" "G92 X0 Y0")
firmware_fuzzer printer3d_interp printer3d_interp printer3d-interp-alone "${marlin[@]}"
firmware_fuzzer printer3d_interp_thesis printer3d_interp_thesis_parser printer3d-interp-thesis "${marlin[@]}"
firmware_fuzzer grbl_stepper grbl_stepper arduino-uno-cnc-shield-v3 "G21 G91" "G1 X1 Y1 F500" '$$' "G0 X2"
firmware_fuzzer delta delta delta-seed004 "G1 X0 Y0 Z-310" "G1 X-33 Y-67 Z-340" "M3" "G1 X-100 Y0 Z-320" "M5"
firmware_fuzzer delta_thesis delta_thesis delta-seed004 "G1 X0 Y0 Z-310" "G1 X-33 Y-67 Z-340" "M3" "G1 X-100 Y0 Z-320" "M5"
