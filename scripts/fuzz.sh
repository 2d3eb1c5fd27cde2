#!/usr/bin/env bash
# Builds the libFuzzer target of the PVS reader with clang (ASan + UBSan) and runs it for a
# bounded time on the committed seed corpus. Exit status non-zero on a finding; the crashing
# input is saved as build-fuzz/crash-* (reproduce: build-fuzz/pvs_reader_fuzz build-fuzz/crash-...).
#
#   bash scripts/fuzz.sh              # 60 s (FUZZ_SECONDS overrides), new inputs in build-fuzz/corpus
#   bash scripts/fuzz.sh merge        # minimise seeds + build-fuzz/corpus into fuzz/corpus/pvs_reader
#
# Needs clang++ and the libFuzzer runtime (Debian: clang, libclang-rt-14-dev). Uses neither vislib
# nor its dependencies: the target compiles pvs_format/ alone.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${FUZZ_BUILD_DIR:-build-fuzz}
SECONDS_TO_RUN=${FUZZ_SECONDS:-60}
SEEDS=fuzz/corpus/pvs_reader
mkdir -p "$BUILD_DIR/corpus"
cmake -S fuzz -B "$BUILD_DIR" -G Ninja -DCMAKE_CXX_COMPILER="${CXX_FUZZ:-clang++}" > "$BUILD_DIR/configure.log" 2>&1 \
  || { cat "$BUILD_DIR/configure.log"; exit 1; }
cmake --build "$BUILD_DIR"
FUZZER="$BUILD_DIR/pvs_reader_fuzz"
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
if [[ "${1:-}" == "merge" ]]; then
  # Keep only inputs that add coverage; replaces the committed seeds by the minimised set.
  rm -rf "$SEEDS.new" && mkdir -p "$SEEDS.new"
  "$FUZZER" -merge=1 "$SEEDS.new" "$SEEDS" "$BUILD_DIR/corpus"
  rm -rf "$SEEDS" && mv "$SEEDS.new" "$SEEDS"
  echo "fuzz: $(ls "$SEEDS" | wc -l) inputs, $(du -sh "$SEEDS" | cut -f1) in $SEEDS"
  exit 0
fi
# New inputs go to the first folder (not committed); the seeds are read only.
"$FUZZER" -max_total_time="$SECONDS_TO_RUN" -max_len=4096 -rss_limit_mb=2048 -timeout=10 \
  -print_final_stats=1 -artifact_prefix="$BUILD_DIR/" "$BUILD_DIR/corpus" "$SEEDS"
echo "fuzz: ${SECONDS_TO_RUN} s without a finding"
