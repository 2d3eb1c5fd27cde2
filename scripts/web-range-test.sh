#!/usr/bin/env bash
# Streaming test of the web client (ctest web_range_1gb): on a PVS file of more than 1 GB written
# directly by the format writer (tests/tools/pvs_synthetic: random sets, no bake), the bytes read
# are the header, the layout section, the index and the blocks of the visited cells (and of their
# Delta chains) only:
#  1. natively, through pvs_rt_open_ranges with a counting read callback (must pass);
#  2. through the range server (scripts/serve_web.py) and the runtime in WebAssembly in headless
#     chromium: the server's log must list exactly the same ranges.
# The 1 GB file is deleted at the end unless VISLIB_KEEP_1GB=1 (then a rerun reuses it).
# Usage: web-range-test.sh PVS_SYNTHETIC WORKDIR. Exit 0 pass, 1 fail (a missing web bundle too),
# 77 chromium cannot start (after part 1 passed). Time budget: writing the file is about
# a minute on an idle core (more on a loaded machine); the checks take seconds.
set -euo pipefail
synth=$1 work=$2
root=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$work"
big=$work/synthetic_1gb.pvs
[[ ${VISLIB_KEEP_1GB:-0} == 1 ]] || trap 'rm -f "$big"' EXIT
# 212 x 212 cells of 8000 ids with 3-byte gaps: about 24 KB per block, 1.08 GB in all.
start=$(date +%s)
if [[ ! -f $big ]]; then
  "$synth" write "$big" --grid 212,212 --ids 8000 --gap-bytes 3 --seed 35 >/dev/null
fi
size=$(stat -c %s "$big")
echo "web-range-test: $big: $size bytes (written in $(($(date +%s) - start)) s)"
[[ $size -ge 1073741824 ]] || { echo "web-range-test: FAIL: the file is under 1 GiB"; exit 1; }
cells=0,1,213,214,22577,44943
"$synth" ranges "$big" --cells $cells >"$work/native.json" ||
  { echo "web-range-test: FAIL: native ranges"; head -c 2000 "$work/native.json"; exit 1; }
python3 - "$work/native.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
print("web-range-test: native: %d bytes read of %d (header+layout+index %d, %d ranges): only the "
      "allowed ranges" % (d["bytes_read"], d["file_size"], d["header_layout_index_bytes"],
                          len(d["ranges"])))
PY

if [[ ! -f $root/web/build/pvs_runtime.wasm || ! -d $root/web/node_modules/puppeteer-core ]] ||
  ! command -v node >/dev/null; then
  echo "web-range-test: FAIL: the web bundle is not built (bash scripts/install-web-deps.sh; bash scripts/build-web.sh)"
  exit 1
fi
stage=$(mktemp -d "${TMPDIR:-/tmp}/vislib-web-range.XXXXXX")
server=""
cleanup() {
  if [[ -n $server ]]; then kill "$server" 2>/dev/null || true; fi
  rm -rf "$stage"
  [[ ${VISLIB_KEEP_1GB:-0} == 1 ]] || rm -f "$big"
}
trap cleanup EXIT
ln -s "$root/web" "$stage/web"
ln -s "$(realpath "$big")" "$stage/big.pvs"
python3 "$root/scripts/serve_web.py" "$stage" --port 0 --port-file "$stage/port" \
  --log "$stage/server.log" 2>/dev/null &
server=$!
for _ in $(seq 100); do [[ -s $stage/port ]] && break; sleep 0.1; done
path=$(python3 -c 'import json,sys; print(";".join("%r,%r,%r" % tuple(c) for c in json.load(open(sys.argv[1]))["centres"]))' "$work/native.json")
set +e
node "$root/web/tools/web_check.mjs" \
  --url "http://127.0.0.1:$(cat "$stage/port")/web/range.html?pvs=/big.pvs&path=$path" \
  --json "$work/browser.json" --server-log "$stage/server.log" --pvs-name big.pvs
rc=$?
set -e
[[ $rc -eq 77 ]] && { echo "web-range-test: SKIPPED the browser half: chromium cannot start"; exit 77; }
[[ $rc -eq 0 ]] || { echo "web-range-test: FAIL: the page failed"; exit 1; }
python3 - "$work/native.json" "$work/browser.json" "$cells" <<'PY'
import json, sys
native = json.load(open(sys.argv[1]))
browser = json.load(open(sys.argv[2]))
cells = [int(c) for c in sys.argv[3].split(",")]
found = [f["cell"] for f in browser["frames"]]
allowed = sorted((a, b - 1) for a, b in native["allowed"])   # inclusive, as HTTP ranges
served = browser["server"]["ranges"]
ok = True
if found != cells:
    print("web-range-test: FAIL: cells found %s, expected %s" % (found, cells)); ok = False
if any(r is None for r in served):
    print("web-range-test: FAIL: a whole-file request"); ok = False
elif sorted(tuple(r) for r in served) != allowed:
    print("web-range-test: FAIL: served ranges %s, allowed %s" % (served, allowed)); ok = False
if browser["server"]["bytes"] != native["allowed_bytes"]:
    print("web-range-test: FAIL: served %d bytes, allowed %d" % (browser["server"]["bytes"],
                                                            native["allowed_bytes"])); ok = False
print("web-range-test: browser: %d requests, %d bytes served of %d (%.4f%%)" % (
    browser["server"]["requests"], browser["server"]["bytes"], native["file_size"],
    100.0 * browser["server"]["bytes"] / native["file_size"]))
sys.exit(0 if ok else 1)
PY
