# web_stage.sh (sourced by view.sh and web-check.sh): stages SCENE and PVS for the web client
# and starts the range server on them.
#   web_stage SCENE PVS [centres]
#                        -> sets STAGE (a temporary folder: web/ linked, scene.glb exported in id
#                           order, the PVS linked), PORT, SERVER_PID, PAGE (the page's URL,
#                           without the query's path) and SERVER_LOG; the caller stops the server.
#                           With `centres`: also centres.json, each cell's near-far centre as
#                           pvs view chooses it (pvs export --centres), named in PAGE.
web_stage() {
  local scene=$1 pvs=$2 centres=${3:-} root
  root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
  local exe=${PVS_EXE:-$root/build/cli/pvs}
  [[ -x $exe ]] || { echo "web: $exe not found (bash scripts/build.sh)" >&2; return 2; }
  [[ -f $root/web/build/pvs_runtime.wasm && -d $root/web/node_modules/three ]] ||
    { echo "web: the web bundle is not built (bash scripts/build-web.sh)" >&2; return 2; }
  [[ -f $scene ]] || { echo "web: $scene: no such file" >&2; return 2; }
  [[ -f $pvs ]] || { echo "web: $pvs: no such file" >&2; return 2; }
  STAGE=$(mktemp -d "${TMPDIR:-/tmp}/vislib-web.XXXXXX")
  ln -s "$root/web" "$STAGE/web"
  # WEB_STATES=K: sample the scene's animation at K states (pvs export --states K), so that the
  # GLB carries them as morph targets and the page knows the moving (dynamic) triangles.
  "$exe" export "$scene" ${WEB_STATES:+--states "$WEB_STATES"} -o "$STAGE/scene.glb" -q \
    ${centres:+--pvs "$pvs" --centres "$STAGE/centres.json"} || return 2
  PVS_NAME=$(basename "$pvs")
  ln -s "$(realpath "$pvs")" "$STAGE/$PVS_NAME"
  SERVER_LOG=$STAGE/server.log
  python3 "$root/scripts/serve_web.py" "$STAGE" --port "${WEB_PORT:-0}" --port-file "$STAGE/port" \
    --log "$SERVER_LOG" 2>"$STAGE/server.err" &
  SERVER_PID=$!
  for _ in $(seq 100); do
    [[ -s $STAGE/port ]] && break
    kill -0 "$SERVER_PID" 2>/dev/null || { cat "$STAGE/server.err" >&2; return 1; }
    sleep 0.1
  done
  PORT=$(cat "$STAGE/port")
  PAGE="http://127.0.0.1:$PORT/web/index.html?scene=/scene.glb&pvs=/$PVS_NAME"
  [[ -z $centres ]] || PAGE+="&centres=/centres.json"
}

web_unstage() {
  if [[ -n ${SERVER_PID:-} ]]; then
    kill "$SERVER_PID" 2>/dev/null || true
    wait "$SERVER_PID" 2>/dev/null || true
  fi
  if [[ -n ${STAGE:-} && -d $STAGE ]]; then rm -rf "$STAGE"; fi
  return 0
}
