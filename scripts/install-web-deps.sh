#!/usr/bin/env bash
# Installs what the web client needs when it is missing, from Debian 12's packages: emscripten
# (builds the runtime in WebAssembly), chromium (the headless check) and node + npm (the page's
# npm packages and puppeteer-core). Prints the time it took.
#
# node and npm: on a fresh Debian 12 both come from Debian (apt-get install nodejs npm). On an
# image whose nodejs comes from elsewhere (NodeSource's nodejs package bundles npm; a node
# installed by hand usually has npm next to it), Debian's npm package conflicts with that
# nodejs, so it is never installed there: an npm on PATH is used as it is, and a foreign nodejs
# without npm is an error that says so.
set -euo pipefail
start=$(date +%s.%N)
SUDO=""
[[ $(id -u) -eq 0 ]] || SUDO=sudo
missing=()
command -v emcc >/dev/null || missing+=(emscripten)
[[ -x /usr/lib/chromium/chromium || -x /usr/bin/chromium ]] || missing+=(chromium)
if ! command -v node >/dev/null; then
  missing+=(nodejs npm)
elif ! command -v npm >/dev/null; then
  node_version=$(dpkg-query -W -f='${Version}' nodejs 2>/dev/null || true)
  if [[ -n $node_version && $node_version != *nodesource* && $node_version == *dfsg* ]]; then
    missing+=(npm)  # Debian's own nodejs: Debian's npm fits it
  else
    echo "install-web-deps: node ($(command -v node), ${node_version:-not a Debian package}) has no npm," >&2
    echo "  and Debian's npm conflicts with a nodejs from elsewhere: install npm with that nodejs" >&2
    echo "  (NodeSource's nodejs package includes it), or remove that nodejs and rerun." >&2
    exit 1
  fi
fi
if [[ ${#missing[@]} -gt 0 ]]; then
  echo "install-web-deps: installing ${missing[*]}"
  for try in 1 2 3 4 5 6; do  # another apt may hold the lock for a while
    if $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends \
      "${missing[@]}"; then
      break
    fi
    [[ $try -eq 6 ]] && exit 1
    $SUDO apt-get update -q || true
    sleep 10
  done
fi
end=$(date +%s.%N)
printf 'install-web-deps: emcc %s, chromium %s, node %s, npm %s (%.0f s)\n' \
  "$(emcc --version 2>/dev/null | sed -n '1s/.*) \([0-9.]*\).*/\1/p')" \
  "$(dpkg-query -W -f='${Version}' chromium 2>/dev/null)" "$(node --version)" "$(npm --version)" \
  "$(awk "BEGIN { print $end - $start }")"
