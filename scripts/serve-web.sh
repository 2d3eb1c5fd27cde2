#!/usr/bin/env bash
# Serves DIR over HTTP with byte-range requests (scripts/serve_web.py), logging every request and
# the bytes it served as a JSON line. Usage: serve-web.sh DIR [--port N] [--log FILE]
set -euo pipefail
exec python3 "$(dirname "$0")/serve_web.py" "$@"
