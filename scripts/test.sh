#!/usr/bin/env bash
# README Quick start (b): install what is missing, build, run the whole test suite with ctest.
# Tests that need ../shared (real scenes by other people) skip cleanly when it is absent.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
BUILD_DIR=${BUILD_DIR:-build} bash scripts/build.sh "$@"
# The web client's bundle, for its ctest checks (emscripten, chromium, node + npm when missing).
# Budget 600 s on 2 cores with the packages to download (about 90 s when they are installed).
web_start=$(date +%s)
bash scripts/install-web-deps.sh
bash scripts/build-web.sh
echo "== web client's dependencies and bundle: $(( $(date +%s) - web_start )) s (budget 600 s)"
cd "${BUILD_DIR:-build}"
ctest --output-on-failure -j "$(nproc)" --timeout 1500 2>&1 | tee ctest.log
