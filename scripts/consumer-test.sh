#!/usr/bin/env bash
# Consumer tests: what an engine or a tool does with an installed vislib, always installed at a
# temporary prefix other than the configured one, and moved after install (the install is
# relocatable: the .pc file, the CMake package files and the image module need no configured path).
#
#   scripts/consumer-test.sh WORK_DIR
#     1. extracts the fenced block of README.md between "<!-- engine-block begin" and
#        "<!-- engine-block end" and runs it from the repository root with only its prefix
#        (/opt/vislib) and build folder (build-rt) replaced: a fresh VISLIB_RUNTIME_ONLY build
#        (configured for the default prefix), installed at the temporary prefix, and
#        examples/engine_loop.c built with cc + pkg-config and run;
#     2. moves the prefix, then builds tests/consumer (an external CMake project:
#        find_package(vislib 0.1 COMPONENTS runtime)) against it with every heavy package disabled
#        (CMAKE_DISABLE_FIND_PACKAGE_<P>) and runs it;
#     3. builds examples/engine_loop.c with plain cc through pkg-config at the moved prefix and
#        runs it.
#   scripts/consumer-test.sh --full BUILD_DIR WORK_DIR [PYTHON]
#     installs the full build BUILD_DIR (`cmake --install BUILD_DIR --prefix TMP`, no new build),
#     moves the prefix, builds and runs tests/consumer/full (find_package(vislib 0.1 COMPONENTS
#     vislib): a scene loaded, an image written and read back), runs the installed `pvs` (a one-cell bake and its frame), and, when
#     PYTHON is given, imports the installed pyvislib with it and renders and saves a frame; the
#     image module must be loaded from the moved prefix.
# "No heavy header visible" (runtime mode): Debian puts Embree, TBB, CGAL, ... in /usr/include,
# which no flag removes from a compiler's search path, so instead every compilation's dependency
# list (ninja's deps log, cc -MD) is checked to name none of their headers, and the programs'
# NEEDED entries are checked. Prints the time of each step; the budget: about a minute on 2 cores
# for each mode.
set -euo pipefail
SRC=$(cd "$(dirname "$0")/.." && pwd)
MODE=runtime
if [ "${1:-}" = --full ]; then
  MODE=full
  BUILD=$(cd "${2:?usage: consumer-test.sh --full BUILD_DIR WORK_DIR [PYTHON]}" && pwd)
  shift 2
fi
WORK=${1:?usage: consumer-test.sh WORK_DIR | consumer-test.sh --full BUILD_DIR WORK_DIR [PYTHON]}
PYTHON=${2:-}
rm -rf "$WORK"
mkdir -p "$WORK"
WORK=$(cd "$WORK" && pwd)
# The prefix: a temporary folder outside the build and source trees (so nothing found above it
# can stand in for what the install lacks), removed at exit.
TMP_ROOT=$(mktemp -d "${TMPDIR:-/tmp}/vislib-consumer.XXXXXX")
trap 'rm -rf "$TMP_ROOT"' EXIT
PREFIX=$TMP_ROOT/prefix
MOVED=$TMP_ROOT/moved/vislib
PVS_FILE=$SRC/tests/golden/pvs_v1_grid.pvs
HEAVY='/(embree[0-9]*|tbb|oneapi|CGAL|OpenMesh|OpenImageIO|boost|gmp|mpfr|tiny_gltf|meshoptimizer|nlohmann|fmt|CLI|gtest|benchmark)[/.]'
LAUNCHER=()
if command -v ccache > /dev/null; then
  LAUNCHER=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
  export CMAKE_CXX_COMPILER_LAUNCHER=ccache CMAKE_C_COMPILER_LAUNCHER=ccache  # for the README block
fi
export CMAKE_BUILD_PARALLEL_LEVEL=${JOBS:-2}
t0=$(date +%s)
step() { echo "consumer-test: $1 ($(( $(date +%s) - t0 )) s so far)"; }
fail() { echo "consumer-test: FAIL: $*"; exit 1; }
no_heavy_headers() {  # $1: what, stdin: a dependency listing
  if grep -E "$HEAVY" > "$WORK/heavy.txt"; then
    echo "consumer-test: FAIL: $1 includes a heavy dependency's header:"; head "$WORK/heavy.txt"; exit 1
  fi
}
configured_prefix() {  # $1: a build folder
  sed -n 's/^CMAKE_INSTALL_PREFIX:[A-Z]*=//p' "$1/CMakeCache.txt"
}
move_prefix() {
  mkdir -p "$(dirname "$MOVED")"
  mv "$PREFIX" "$MOVED"
  step "prefix moved to $MOVED"
}

if [ "$MODE" = runtime ]; then
  # 1. The README's engine block, verbatim but for the prefix and the build folder.
  awk '/^<!-- engine-block begin/ {on = 1; next} /^<!-- engine-block end/ {on = 0}
       on && /^```/ {fence = !fence; next} on && fence {print}' "$SRC/README.md" > "$WORK/readme-block.txt"
  if ! grep -q /opt/vislib "$WORK/readme-block.txt" || ! grep -q build-rt "$WORK/readme-block.txt"; then
    fail "README.md has no engine block (markers '<!-- engine-block begin/end' around a fenced block naming /opt/vislib and build-rt)"
  fi
  sed -e "s|/opt/vislib|$PREFIX|g" -e "s|build-rt|$WORK/runtime-build|g" "$WORK/readme-block.txt" > "$WORK/readme-block.sh"
  echo "consumer-test: README.md's engine block, run from $SRC:"; sed 's/^/  | /' "$WORK/readme-block.sh"
  (cd "$SRC" && bash -euo pipefail "$WORK/readme-block.sh") > "$WORK/readme-block.log" 2>&1 \
    || { tail -40 "$WORK/readme-block.log"; fail "README.md's engine block failed ($WORK/readme-block.log)"; }
  tail -1 "$WORK/readme-block.log"
  grep -q "^100 frames, " "$WORK/readme-block.log" || fail "engine_loop did not run its 100 frames"
  configured=$(configured_prefix "$WORK/runtime-build")
  [ "$configured" != "$PREFIX" ] || fail "the block configured the prefix it installed to"
  if grep -E -i "embree|tbb|cgal|openmesh|openimageio" "$WORK/runtime-build/CMakeCache.txt" | grep -v -E "^(//|VISLIB_|CMAKE_)" | grep -q .; then
    fail "the runtime-only configure looked for a heavy package"
  fi
  ninja -C "$WORK/runtime-build" -t deps | no_heavy_headers "the runtime-only build"
  step "README.md's engine block: configured for $configured, installed at $PREFIX, engine_loop run"
  move_prefix

  # 2. An external CMake project on the moved prefix.
  DISABLE=()
  for p in embree TBB CGAL OpenMesh OpenImageIO TinyGLTF meshoptimizer nlohmann_json GTest benchmark; do
    DISABLE+=("-DCMAKE_DISABLE_FIND_PACKAGE_$p=ON")
  done
  cmake -S "$SRC/tests/consumer" -B "$WORK/consumer-build" -G Ninja -DCMAKE_PREFIX_PATH="$MOVED" \
    -DPVS_FILE="$PVS_FILE" "${DISABLE[@]}" "${LAUNCHER[@]}" > "$WORK/consumer-configure.log" 2>&1 \
    || { cat "$WORK/consumer-configure.log"; exit 1; }
  grep "vislib 0" "$WORK/consumer-configure.log"
  grep -q "from $MOVED/" "$WORK/consumer-configure.log" || fail "find_package did not find the moved prefix"
  cmake --build "$WORK/consumer-build" > "$WORK/consumer-build.log" 2>&1 || { cat "$WORK/consumer-build.log"; exit 1; }
  ninja -C "$WORK/consumer-build" -t deps | no_heavy_headers "the consumer project"
  (cd "$WORK/consumer-build" && ctest --output-on-failure -V | grep -E "^[0-9]+: consumer_|tests passed")
  step "find_package consumer built and run on the moved prefix"

  # 3. engine_loop.c with cc + pkg-config on the moved prefix.
  export PKG_CONFIG_PATH=$MOVED/lib/pkgconfig
  CC=${CC:-cc}
  flags=$(pkg-config --cflags --libs vislib_runtime)
  echo "consumer-test: pkg-config --cflags --libs vislib_runtime: $flags"
  case "$flags" in *"-I$MOVED/"*"-L$MOVED/"*) ;; *) fail "pkg-config does not name the moved prefix";; esac
  # shellcheck disable=SC2086
  $CC -std=c99 -Wall -Wextra -Werror -MD -MF "$WORK/engine_loop.d" "$SRC/examples/engine_loop.c" -o "$WORK/engine_loop" $flags
  no_heavy_headers "engine_loop.c" < "$WORK/engine_loop.d"
  needed=$(readelf -d "$WORK/engine_loop" | sed -nE 's/.*NEEDED.*\[(.*)\]/\1/p' | sort | paste -sd' ')
  echo "consumer-test: engine_loop needs: $needed"
  case " $needed " in *" libvislib_runtime.so.0.1 "*) ;; *) fail "engine_loop does not link libvislib_runtime";; esac
  case " $needed " in *stdc++*) fail "engine_loop needs libstdc++ directly";; esac
  LD_LIBRARY_PATH=$MOVED/lib "$WORK/engine_loop" "$PVS_FILE" --frames 50 > "$WORK/engine_loop.out"
  tail -1 "$WORK/engine_loop.out"
  grep -q "^50 frames, " "$WORK/engine_loop.out"
  # The shared library's ABI is the C API: nothing but pvs_rt_* is exported.
  so=$MOVED/lib/libvislib_runtime.so
  others=$(nm -D --defined-only "$so" | awk '$2 ~ /^[TDBRVW]$/ {print $3}' | grep -v '^pvs_rt_' || true)
  [ -z "$others" ] || { echo "consumer-test: FAIL: libvislib_runtime.so exports C++ symbols:"; echo "$others" | head; exit 1; }
  step "engine_loop.c built with cc + pkg-config and run; libvislib_runtime.so exports $(nm -D --defined-only "$so" | grep -c ' T pvs_rt_') pvs_rt_* functions only"
  echo "consumer-test: passed in $(( $(date +%s) - t0 )) s"
  exit 0
fi

# --full: the current full build, installed (not rebuilt) at the temporary prefix.
[ -f "$BUILD/cmake_install.cmake" ] || fail "$BUILD is not a configured build folder"
configured=$(configured_prefix "$BUILD")
cmake --install "$BUILD" --prefix "$PREFIX" > "$WORK/install.log" 2>&1 || { tail -20 "$WORK/install.log"; fail "cmake --install $BUILD"; }
[ "$configured" != "$PREFIX" ] || fail "the build was configured for the prefix it is installed at"
# The package files name no configure-time folder: neither the build nor the source tree, nor the
# configured prefix (unless it is / or /usr, where Debian's own packages live).
stale=("$BUILD" "$SRC")
case "$configured" in /|/usr) ;; *) stale+=("$configured");; esac
for s in "${stale[@]}"; do
  if grep -rnF "$s" "$PREFIX/lib/cmake" "$PREFIX/lib/pkgconfig" > "$WORK/stale.txt"; then
    head "$WORK/stale.txt"; fail "an installed package file names $s"
  fi
done
step "full build $BUILD (configured for $configured) installed at $PREFIX"
move_prefix

# The whole library from an external CMake project.
cmake -S "$SRC/tests/consumer/full" -B "$WORK/consumer-full-build" -G Ninja -DCMAKE_PREFIX_PATH="$MOVED" \
  -DSCENE_FILE="$SRC/data/city.glb" "${LAUNCHER[@]}" > "$WORK/consumer-configure.log" 2>&1 \
  || { cat "$WORK/consumer-configure.log"; exit 1; }
grep "vislib 0" "$WORK/consumer-configure.log"
grep -q "from $MOVED/.*image module $MOVED/" "$WORK/consumer-configure.log" || fail "find_package did not find the moved prefix"
cmake --build "$WORK/consumer-full-build" > "$WORK/consumer-build.log" 2>&1 || { cat "$WORK/consumer-build.log"; exit 1; }
(cd "$WORK/consumer-full-build" && ctest --output-on-failure -V | grep -E "^[0-9]+: consumer_|tests passed")
step "find_package(vislib COMPONENTS vislib) consumer built and run on the moved prefix"

# The image module, loaded by the installed pvs and pyvislib from their own location: the loader
# must report a file under the moved prefix.
module_loaded_from() {  # $1: an LD_DEBUG=files log
  sed -nE 's/.*file=([^ ]*vislib_image_oiio[^ ]*) .*dynamically loaded.*/\1/p' "$1" | head -1
}
"$MOVED/bin/pvs" --version
# A one-cell bake of the default scene around its centre crossing, and the frame of that cell.
"$MOVED/bin/pvs" bake "$SRC/data/city.glb" --box -4,1,-4,4,2,4 --grid 1,1,1 --res 16 --runs 1 -o "$WORK/tiny.pvs" -q
LD_DEBUG=files LD_DEBUG_OUTPUT="$WORK/pvs-ld" "$MOVED/bin/pvs" view "$WORK/tiny.pvs" --scene "$SRC/data/city.glb" \
  --at 0,1.5,0 --look 1,1.5,0 --frame 32x24 -o "$WORK/tiny.png" -q
loaded=$(cat "$WORK"/pvs-ld.* | module_loaded_from /dev/stdin)
echo "consumer-test: the installed pvs loaded the image module from $loaded"
case "$loaded" in "$MOVED/lib/vislib/"*) ;; *) fail "the installed pvs did not load the moved prefix's image module";; esac
[ -s "$WORK/tiny.png" ] || fail "pvs view wrote no frame"
step "installed pvs ran and wrote a frame"

if [ -z "$PYTHON" ]; then
  echo "consumer-test: pyvislib not built: the Python check is skipped"
else
  module=$(find "$MOVED" -name 'pyvislib*.so')
  [ -n "$module" ] || fail "pyvislib is not installed under $MOVED"
  pydir=$(dirname "$module")
  echo "consumer-test: pyvislib installed at ${pydir#"$MOVED"/}"
  if readelf -d "$module" | grep -E "R(UN)?PATH" | grep -qF "$BUILD"; then fail "pyvislib's RUNPATH names the build folder"; fi
  (cd "$WORK" && LD_DEBUG=files LD_DEBUG_OUTPUT="$WORK/py-ld" PYTHONPATH="$pydir" PYTHONDONTWRITEBYTECODE=1 "$PYTHON" -c "
import os, sys
import pyvislib as v
assert os.path.realpath(v.__file__).startswith(os.path.realpath(sys.argv[1])), v.__file__
scene = v.load_scene(sys.argv[2])
frame = v.Renderer(scene).render(eye=(0, 1.5, 0), forward=(1, 0, 0), width=32, height=24)
frame.save('py.png')
print('consumer-test: import pyvislib from', v.__file__, '->', scene.triangle_count, 'triangles, frame saved')
" "$MOVED" "$SRC/data/city.glb")
  loaded=$(cat "$WORK"/py-ld.* | module_loaded_from /dev/stdin)
  echo "consumer-test: the installed pyvislib loaded the image module from $loaded"
  case "$loaded" in "$MOVED/lib/vislib/"*) ;; *) fail "the installed pyvislib did not load the moved prefix's image module";; esac
  [ -s "$WORK/py.png" ] || fail "pyvislib saved no frame"
  step "installed pyvislib imported, rendered and saved a frame"
fi
echo "consumer-test: passed in $(( $(date +%s) - t0 )) s"
