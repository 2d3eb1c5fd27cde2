#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (ASan + UBSan) and runs each for a bounded time on its
# committed seed corpus: the PVS reader and the scene loaders of every format (glb gltf obj ply off
# stl spheres bsp). Exit status non-zero on a finding; the crashing input is saved as
# build-fuzz/<target>/crash-* (reproduce: build-fuzz/<target> build-fuzz/<target>/crash-...).
#
#   bash scripts/fuzz.sh                  # every target, FUZZ_SECONDS (default 240) split evenly
#   FUZZ_SECONDS_PER_TARGET=600 bash scripts/fuzz.sh ply_loader_fuzz   # one target, 10 minutes
#   bash scripts/fuzz.sh merge [TARGET]   # minimise seeds + new inputs into fuzz/corpus/<name>
#
# Before fuzzing, every seed (the crash repros among them) is run once through its target, and
# when ../shared/repros and build/cli/pvs exist, `pvs info` must exit 2 on each repro.
# Needs clang++ and the libFuzzer runtime (Debian: clang, libclang-rt-14-dev), and for the scene
# loaders the Debian packages of tinygltf, meshoptimizer and nlohmann-json (as vislib itself).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${FUZZ_BUILD_DIR:-build-fuzz}
ALL_TARGETS="pvs_reader_fuzz glb_loader_fuzz gltf_loader_fuzz obj_loader_fuzz ply_loader_fuzz off_loader_fuzz stl_loader_fuzz spheres_loader_fuzz bsp_loader_fuzz"
mode=run
if [[ "${1:-}" == "merge" ]]; then mode=merge; shift; fi
TARGETS=${*:-$ALL_TARGETS}
ntargets=$(wc -w <<< "$TARGETS")
TOTAL=${FUZZ_SECONDS:-240}
PER_TARGET=${FUZZ_SECONDS_PER_TARGET:-$(( TOTAL / ntargets ))}
(( PER_TARGET >= 1 )) || PER_TARGET=1
mkdir -p "$BUILD_DIR"
cmake -S fuzz -B "$BUILD_DIR" -G Ninja -DCMAKE_CXX_COMPILER="${CXX_FUZZ:-clang++}" > "$BUILD_DIR/configure.log" 2>&1 \
  || { cat "$BUILD_DIR/configure.log"; exit 1; }
cmake --build "$BUILD_DIR" --target $TARGETS
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
seeds_of() { local t=${1%_fuzz}; echo "fuzz/corpus/${t%_loader}"; }

if [[ $mode == merge ]]; then
  for t in $TARGETS; do
    seeds=$(seeds_of "$t")
    # Keep only inputs that add coverage; replaces the committed seeds by the minimised set.
    rm -rf "$seeds.new" && mkdir -p "$seeds.new" "$BUILD_DIR/corpus/$t"
    "$BUILD_DIR/$t" -merge=1 "$seeds.new" "$seeds" "$BUILD_DIR/corpus/$t"
    rm -rf "$seeds" && mv "$seeds.new" "$seeds"
    echo "fuzz: $t: $(ls "$seeds" | wc -l) inputs, $(du -sh "$seeds" | cut -f1) in $seeds"
  done
  exit 0
fi

# The crash repros of ../shared/repros through the CLI: exit 2 with a message, quickly.
if [[ -d ../shared/repros && -x build/cli/pvs ]]; then
  for f in ../shared/repros/ply-*.ply ../shared/repros/off-oom.off; do
    [[ -e $f ]] || continue
    t0=$(date +%s%N)
    rc=0; msg=$(timeout 10 build/cli/pvs info "$f" 2>&1 >/dev/null) || rc=$?
    ms=$(( ($(date +%s%N) - t0) / 1000000 ))
    [[ $rc == 2 ]] || { echo "fuzz: repro $f: exit $rc (expected 2) after $ms ms: $msg"; exit 1; }
    echo "fuzz: repro $(basename "$f"): exit 2 in $ms ms: $msg"
  done
fi

# The Quake maps of ../shared (too large to fuzz from: megabytes) run once through the BSP target:
# none may crash the loader. The committed seeds are small maps the tests generate (tests/quake_bsp_test.cpp).
if [[ " $TARGETS " == *" bsp_loader_fuzz "* && -d ../shared/scenes/librequake ]]; then
  "$BUILD_DIR/bsp_loader_fuzz" -runs=1 ../shared/scenes/librequake/*.bsp > "$BUILD_DIR/bsp_shared.log" 2>&1 \
    || { tail -40 "$BUILD_DIR/bsp_shared.log"; echo "fuzz: bsp_loader_fuzz: a shared map failed"; exit 1; }
  echo "fuzz: bsp_loader_fuzz: the maps of ../shared/scenes/librequake ran without a finding"
fi

echo "fuzz: $ntargets target(s), ${PER_TARGET} s each"
for t in $TARGETS; do
  seeds=$(seeds_of "$t")
  mkdir -p "$BUILD_DIR/corpus/$t" "$BUILD_DIR/$t.artifacts"
  # New inputs go to the first folder (not committed); the seeds are read only.
  status=0
  "$BUILD_DIR/$t" -max_total_time="$PER_TARGET" -max_len=4096 -rss_limit_mb=2048 -malloc_limit_mb=1024 \
    -timeout=10 -print_final_stats=1 -artifact_prefix="$BUILD_DIR/$t.artifacts/" \
    "$BUILD_DIR/corpus/$t" "$seeds" > "$BUILD_DIR/$t.log" 2>&1 || status=$?
  grep -E "^#[0-9]+[[:space:]]+(INITED|DONE)|^stat::number_of_executed_units" "$BUILD_DIR/$t.log" || true
  if [[ $status != 0 ]]; then
    tail -40 "$BUILD_DIR/$t.log"
    echo "fuzz: $t: FINDING (exit $status), input in $BUILD_DIR/$t.artifacts/"
    exit 1
  fi
  echo "fuzz: $t: ${PER_TARGET} s without a finding"
done
