#!/usr/bin/env bash
# Builds the web client (web/): the PVS runtime (pvs_format/ + runtime/, the C API exported) in
# WebAssembly with Debian's emscripten, into web/build/pvs_runtime.{js,wasm}, and installs the
# page's npm packages (three, puppeteer-core) from web/package-lock.json. Prints the sizes.
# Needs emcc and npm (bash scripts/install-web-deps.sh installs them).
set -euo pipefail
cd "$(dirname "$0")/.."
if ! command -v emcc >/dev/null; then
  echo "build-web.sh: emcc not found (run: bash scripts/install-web-deps.sh)" >&2
  exit 2
fi
# Debian's emscripten runs its JS optimiser with Debian's acorn, found through NODE_PATH.
export NODE_PATH=/usr/share/nodejs${NODE_PATH:+:$NODE_PATH}
out=web/build
gen=build-web/generated/runtime
mkdir -p "$out" "$gen"
version=$(sed -n 's/^project(vislib VERSION \([0-9.]*\).*/\1/p' CMakeLists.txt)
IFS=. read -r major minor patch <<<"$version"
sed -e "s/@PROJECT_VERSION_MAJOR@/$major/" -e "s/@PROJECT_VERSION_MINOR@/$minor/" \
  -e "s/@PROJECT_VERSION_PATCH@/$patch/" -e "s/@PROJECT_VERSION@/$version/" \
  runtime/vislib_version.h.in >"$gen/vislib_version.h.tmp"
cmp -s "$gen/vislib_version.h.tmp" "$gen/vislib_version.h" 2>/dev/null ||
  mv "$gen/vislib_version.h.tmp" "$gen/vislib_version.h"
rm -f "$gen/vislib_version.h.tmp"

# Every PVS_RT_API function of the runtime's C headers, plus the web entry point and malloc/free.
exports=$(grep -ho '^PVS_RT_API [^(]*(' runtime/*_c.h | sed 's/.*[ *]\(pvs_rt_[a-z0-9_]*\)(/"_\1"/' |
  sort -u | paste -sd, -)
exports="[$exports,\"_pvs_web_open\",\"_malloc\",\"_free\"]"

# -fexceptions: the C API maps the reader's exceptions to status codes, so they must be caught.
flags=(-O2 -std=c++17 -fexceptions -I. -Ibuild-web/generated)
objs=()
mkdir -p build-web/obj
for src in pvs_format/*.cpp runtime/*.cpp; do
  obj=build-web/obj/$(echo "$src" | tr / _).o
  if [[ ! -f $obj || $src -nt $obj || -n $(find pvs_format runtime -name '*.h' -newer "$obj") ]]; then
    em++ "${flags[@]}" -c "$src" -o "$obj"
  fi
  objs+=("$obj")
done
emcc -O2 -I. -Ibuild-web/generated -c web/wasm/pvs_web.c -o build-web/obj/pvs_web.o
em++ -O2 -fexceptions "${objs[@]}" build-web/obj/pvs_web.o -o "$out/pvs_runtime.js" \
  -sMODULARIZE=1 -sEXPORT_NAME=createPvsRuntime -sENVIRONMENT=worker -sALLOW_MEMORY_GROWTH=1 \
  -sEXPORTED_FUNCTIONS="$exports" -sEXPORTED_RUNTIME_METHODS='["UTF8ToString"]'

if [[ -f web/package-lock.json ]] && command -v npm >/dev/null; then
  if [[ ! -d web/node_modules/three || web/package-lock.json -nt web/node_modules/.package-lock.json ]]; then
    # puppeteer-core never downloads a browser; the test drives Debian's chromium.
    (cd web && PUPPETEER_SKIP_DOWNLOAD=1 npm ci --no-audit --no-fund --offline 2>/dev/null ||
      PUPPETEER_SKIP_DOWNLOAD=1 npm ci --no-audit --no-fund)
  fi
fi
wasm_bytes=$(stat -c %s "$out/pvs_runtime.wasm")
wasm_gz=$(gzip -9 -c "$out/pvs_runtime.wasm" | wc -c)
js_bytes=$(stat -c %s "$out/pvs_runtime.js")
js_gz=$(gzip -9 -c "$out/pvs_runtime.js" | wc -c)
echo "web/build/pvs_runtime.wasm: $wasm_bytes bytes ($wasm_gz gzip -9); pvs_runtime.js: $js_bytes bytes ($js_gz gzip -9)"
