#!/usr/bin/env bash
# Checks the arrows between vislib's corners (vislib/corners.txt, README "Corners").
#   check-corners.sh [ROOT]              every quoted include "vislib/<corner>/..." in vislib/<c>/ names
#                                        c or an allowed corner; no relative "../" include; no
#                                        forbidden third-party header (Embree in the kernel, ...).
#   check-corners.sh --self-test [ROOT]  copies ROOT's vislib/ and injects wrong arrows one at a time:
#                                        passes only if the check rejects every one.
#   check-corners.sh --compile CXX BUILD_DIR [ROOT]
#                                        compiles, for every pair of corners (c, d), a file including
#                                        one header of d with c's staged include tree only: it must
#                                        compile exactly when d is c or allowed for c.
# Exit 0 when the arrows hold, 1 with one line per violation otherwise.
set -uo pipefail
mode=sources
case "${1:-}" in
  --self-test) mode=self; shift ;;
  --compile) mode=compile; CXX=$2; BUILD_DIR=$3; shift 3 ;;
esac
ROOT=$(cd "${1:-$(dirname "$0")/..}" && pwd)
TABLE=$ROOT/vislib/corners.txt
[ -f "$TABLE" ] || { echo "check-corners: no $TABLE"; exit 1; }

declare -A ALLOWED FORBIDDEN
CORNERS=()
while IFS= read -r line; do
  line=${line%%#*}
  [[ $line =~ ^[[:space:]]*([a-z_]+):([^|]*)\|?(.*)$ ]] || continue
  c=${BASH_REMATCH[1]}
  CORNERS+=("$c")
  ALLOWED[$c]=" $c $(echo ${BASH_REMATCH[2]}) "
  FORBIDDEN[$c]=$(echo ${BASH_REMATCH[3]})
done < "$TABLE"

check_sources() {  # $1 = root; prints violations, returns 1 if any
  local root=$1 bad=0 c f inc target
  for c in "${CORNERS[@]}"; do
    for f in "$root"/vislib/"$c"/*.h "$root"/vislib/"$c"/*.cpp; do
      [ -f "$f" ] || continue
      while IFS= read -r inc; do
        if [[ $inc =~ ^[[:space:]]*#[[:space:]]*include[[:space:]]*\"vislib/([a-z_]+)/ ]]; then
          target=${BASH_REMATCH[1]}
          if [[ ${ALLOWED[$c]} != *" $target "* ]]; then
            echo "${f#$root/}: corner '$c' may not include corner '$target': $inc"; bad=1
          fi
        elif [[ $inc =~ ^[[:space:]]*#[[:space:]]*include[[:space:]]*\"(\.\./|\./|[^/\"]*\") ]]; then
          echo "${f#$root/}: relative include (write \"vislib/<corner>/<file>\"): $inc"; bad=1
        elif [[ $inc =~ ^[[:space:]]*#[[:space:]]*include[[:space:]]*\"vislib/[^/]*\" ]]; then
          echo "${f#$root/}: include outside the corners: $inc"; bad=1
        elif [[ $inc =~ ^[[:space:]]*#[[:space:]]*include[[:space:]]*\"(cli|tests|runtime)/ ]] &&
             ! { [[ ${ALLOWED[$c]} == *" runtime "* ]] && [[ $inc == *'"runtime/'* ]]; }; then
          echo "${f#$root/}: corner '$c' may not include ${BASH_REMATCH[1]}/: $inc"; bad=1
        elif [ -n "${FORBIDDEN[$c]}" ] && [[ $inc =~ ^[[:space:]]*#[[:space:]]*include[[:space:]]*\<([^>]*)\> ]] &&
             hdr=${BASH_REMATCH[1]} && [[ $hdr =~ ^(${FORBIDDEN[$c]}) ]]; then
          echo "${f#$root/}: corner '$c' may not use <$hdr>"; bad=1
        fi
      done < <(grep -E '^[[:space:]]*#[[:space:]]*include' "$f")
    done
  done
  # Every source file of vislib/ lies in a corner.
  for f in "$root"/vislib/*.h "$root"/vislib/*.cpp; do
    [ -f "$f" ] && { echo "${f#$root/}: not in a corner folder"; bad=1; }
  done
  return $bad
}

case $mode in
sources)
  check_sources "$ROOT" && echo "check-corners: arrows hold in ${#CORNERS[@]} corners"
  ;;
self)
  tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
  check_sources "$ROOT" > /dev/null || { echo "self-test: the tree itself fails the check"; exit 1; }
  fails=0 n=0
  inject() {  # $1 = file relative to vislib/, $2 = line to prepend
    rm -rf "$tmp/vislib"; cp -r "$ROOT/vislib" "$tmp/vislib"
    printf '%s\n' "$2" | cat - "$tmp/vislib/$1" > "$tmp/x" && mv "$tmp/x" "$tmp/vislib/$1"
    n=$((n + 1))
    if check_sources "$tmp" > "$tmp/out"; then
      echo "self-test: NOT rejected: '$2' in vislib/$1"; fails=1
    else
      echo "self-test: rejected as expected: $(head -1 "$tmp/out")"
    fi
  }
  inject kernel/footprint.cpp '#include "vislib/eval/embree_scene.h"'
  inject kernel/segment_visibility.h '#include <embree3/rtcore.h>'
  inject base/vec.h '#include "vislib/scene/scene.h"'
  inject scene/scene.cpp '#include "../kernel/interval_list.h"'
  inject eval/metrics.cpp '#include "vislib/bake/bake.h"'
  inject bake/bake.cpp '#include "vislib/render/near_far_render.h"'
  inject kernel/interval_list.cpp '#include "runtime/near_far.h"'
  inject base/vec.h '#include "cli/commands.h"'
  [ $fails = 0 ] && echo "self-test: all $n wrong arrows rejected"
  exit $fails
  ;;
compile)
  tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
  fails=0
  for c in "${CORNERS[@]}"; do
    for d in "${CORNERS[@]}"; do
      h=$(cd "$ROOT/vislib/$d" && ls *.h | head -1)
      printf '#include "vislib/%s/%s"\nint main() { return 0; }\n' "$d" "$h" > "$tmp/t.cpp"
      if "$CXX" -std=c++17 -fsyntax-only -I "$BUILD_DIR/corner_include/$c" -I "$BUILD_DIR/corner_include/_pvs_format" \
           -I "$BUILD_DIR/corner_include/_runtime" \
           "$tmp/t.cpp" 2> "$tmp/err"; then got=compiles; else got=fails; fi
      if [[ ${ALLOWED[$c]} == *" $d "* ]]; then want=compiles; else want=fails; fi
      if [ $got != $want ]; then
        echo "check-corners: corner '$c' including vislib/$d/$h $got (expected: $want)"; head -3 "$tmp/err"; fails=1
      fi
    done
  done
  [ $fails = 0 ] && echo "check-corners: every corner compiles against exactly its allowed corners"
  exit $fails
  ;;
esac
