#!/usr/bin/env bash
# Consumer tests: what an engine does with vislib, on a runtime-only build.
#   scripts/consumer-test.sh WORK_DIR
# 1. configures a fresh VISLIB_RUNTIME_ONLY build of this tree in WORK_DIR/runtime-build and
#    installs it into WORK_DIR/prefix;
# 2. builds tests/consumer (an external CMake project: find_package(vislib 0.1 COMPONENTS runtime))
#    against that prefix with every heavy package disabled (CMAKE_DISABLE_FIND_PACKAGE_<P>), runs it;
# 3. builds examples/engine_loop.c with plain `cc` through pkg-config and runs it.
# "No heavy header visible": Debian puts Embree, TBB, CGAL, ... in /usr/include, which no flag
# removes from a compiler's search path, so instead every compilation's dependency list (ninja's
# deps log, cc -MD) is checked to name none of their headers, and the programs' NEEDED entries are
# checked. Prints the time of each step (the budget: about a minute on 2 loaded cores).
set -euo pipefail
SRC=$(cd "$(dirname "$0")/.." && pwd)
WORK=${1:?usage: consumer-test.sh WORK_DIR}
rm -rf "$WORK"
mkdir -p "$WORK"
WORK=$(cd "$WORK" && pwd)
PREFIX=$WORK/prefix
PVS_FILE=$SRC/tests/golden/pvs_v1_grid.pvs
HEAVY='/(embree[0-9]*|tbb|oneapi|CGAL|OpenMesh|OpenImageIO|boost|gmp|mpfr|tiny_gltf|meshoptimizer|nlohmann|fmt|CLI|gtest|benchmark)[/.]'
LAUNCHER=()
command -v ccache > /dev/null && LAUNCHER=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
t0=$(date +%s)
step() { echo "consumer-test: $1 ($(( $(date +%s) - t0 )) s so far)"; }
no_heavy_headers() {  # $1: what, stdin: a dependency listing
  if grep -E "$HEAVY" > "$WORK/heavy.txt"; then
    echo "consumer-test: FAIL: $1 includes a heavy dependency's header:"; head "$WORK/heavy.txt"; exit 1
  fi
}

cmake -S "$SRC" -B "$WORK/runtime-build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DVISLIB_RUNTIME_ONLY=ON \
  -DCMAKE_INSTALL_PREFIX="$PREFIX" "${LAUNCHER[@]}" > "$WORK/runtime-configure.log" 2>&1 \
  || { cat "$WORK/runtime-configure.log"; exit 1; }
if grep -E -i "embree|tbb|cgal|openmesh|openimageio" "$WORK/runtime-build/CMakeCache.txt" | grep -v -E "^(//|VISLIB_|CMAKE_)" | grep -q .; then
  echo "consumer-test: FAIL: the runtime-only configure looked for a heavy package"; exit 1
fi
cmake --build "$WORK/runtime-build" -j "${JOBS:-2}" > "$WORK/runtime-build.log" 2>&1 || { cat "$WORK/runtime-build.log"; exit 1; }
ninja -C "$WORK/runtime-build" -t deps | no_heavy_headers "the runtime-only build"
cmake --install "$WORK/runtime-build" > "$WORK/install.log"
step "runtime-only build installed into $PREFIX"

DISABLE=()
for p in embree TBB CGAL OpenMesh OpenImageIO TinyGLTF meshoptimizer nlohmann_json GTest benchmark; do
  DISABLE+=("-DCMAKE_DISABLE_FIND_PACKAGE_$p=ON")
done
cmake -S "$SRC/tests/consumer" -B "$WORK/consumer-build" -G Ninja -DCMAKE_PREFIX_PATH="$PREFIX" \
  -DPVS_FILE="$PVS_FILE" "${DISABLE[@]}" "${LAUNCHER[@]}" > "$WORK/consumer-configure.log" 2>&1 \
  || { cat "$WORK/consumer-configure.log"; exit 1; }
grep "vislib 0" "$WORK/consumer-configure.log"
cmake --build "$WORK/consumer-build" > "$WORK/consumer-build.log" 2>&1 || { cat "$WORK/consumer-build.log"; exit 1; }
ninja -C "$WORK/consumer-build" -t deps | no_heavy_headers "the consumer project"
(cd "$WORK/consumer-build" && ctest --output-on-failure -V | grep -E "^[0-9]+: consumer_|tests passed")
step "find_package consumer built and run"

export PKG_CONFIG_PATH=$PREFIX/lib/pkgconfig
CC=${CC:-cc}
# shellcheck disable=SC2046
$CC -std=c99 -Wall -Wextra -Werror -MD -MF "$WORK/engine_loop.d" "$SRC/examples/engine_loop.c" -o "$WORK/engine_loop" \
  $(pkg-config --cflags --libs vislib_runtime)
no_heavy_headers "engine_loop.c" < "$WORK/engine_loop.d"
needed=$(readelf -d "$WORK/engine_loop" | sed -nE 's/.*NEEDED.*\[(.*)\]/\1/p' | sort | paste -sd' ')
echo "consumer-test: engine_loop needs: $needed"
case " $needed " in *" libvislib_runtime.so.0.1 "*) ;; *) echo "consumer-test: FAIL: engine_loop does not link libvislib_runtime"; exit 1;; esac
case " $needed " in *stdc++*) echo "consumer-test: FAIL: engine_loop needs libstdc++ directly"; exit 1;; esac
LD_LIBRARY_PATH=$PREFIX/lib "$WORK/engine_loop" "$PVS_FILE" --frames 50 > "$WORK/engine_loop.out"
tail -1 "$WORK/engine_loop.out"
grep -q "^50 frames, " "$WORK/engine_loop.out"
# The shared library's ABI is the C API: nothing but pvs_rt_* is exported.
others=$(nm -D --defined-only "$PREFIX/lib/libvislib_runtime.so" | awk '$2 ~ /^[TDBRVW]$/ {print $3}' | grep -v '^pvs_rt_' || true)
[ -z "$others" ] || { echo "consumer-test: FAIL: libvislib_runtime.so exports C++ symbols:"; echo "$others" | head; exit 1; }
step "engine_loop.c built with cc + pkg-config and run; libvislib_runtime.so exports $(nm -D --defined-only "$PREFIX/lib/libvislib_runtime.so" | grep -c ' T pvs_rt_') pvs_rt_* functions only"
echo "consumer-test: passed in $(( $(date +%s) - t0 )) s"
