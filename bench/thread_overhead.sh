#!/usr/bin/env bash
# thread_overhead.sh: what a bake's threads cost, for one or more `pvs` binaries in one run
# (docs/performance.md, "Where a bake's threads spend their time").
#
#   bench/thread_overhead.sh SCENE "J1 J2 ..." PVS... -- BAKE OPTIONS...
#
# Bakes SCENE with each binary at each -j (binaries alternating within each -j, so the host's
# load falls on all of them alike), under /usr/bin/time -v, and prints per bake: process CPU
# seconds (user + sys), peak RSS, wall seconds, and the bake's own timers by phase (--json
# timings.phases: wall / CPU seconds summed over threads); then per binary the overhead, CPU at
# each -j over CPU at the first, and whether every file is byte-identical (cmp). Outputs go to
# a temporary folder (THREAD_OVERHEAD_DIR overrides it), removed unless KEEP=1.
set -euo pipefail
if [ $# -lt 4 ]; then
  sed -n '2,11p' "$0"
  exit 2
fi
scene=$1
threads=$2
shift 2
binaries=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do
  binaries+=("$1")
  shift
done
[ "${1:-}" = "--" ] && shift
dir=${THREAD_OVERHEAD_DIR:-$(mktemp -d)}
mkdir -p "$dir"

printf '%-4s %-3s %9s %9s %8s  %s\n' bin j cpu_s rss_mb wall_s "phases (wall / CPU s)"
for j in $threads; do
  for b in "${!binaries[@]}"; do
    out="$dir/b$b-j$j"
    /usr/bin/time -v "${binaries[$b]}" bake "$scene" "$@" -j "$j" -q --json "$out.json" \
      -o "$out.pvs" 2> "$out.time"
    python3 - "$out" "$b" "$j" <<'EOF'
import json, re, sys
out, b, j = sys.argv[1:4]
t = open(out + ".time").read()
num = lambda k: float(re.search(k + r".*?: ([0-9.:]+)", t).group(1).split(":")[-1])
wall = re.search(r"Elapsed \(wall clock\) time.*?: ([0-9:.]+)", t).group(1).split(":")
wall = sum(float(x) * 60 ** i for i, x in enumerate(reversed(wall)))
cpu = num("User time") + num("System time")
rss = num("Maximum resident set size") / 1024
ph = json.load(open(out + ".json"))["timings"].get("phases", {})  # none before the timers
phases = " ".join(f"{k} {v['wall_seconds']:.1f}/{v['cpu_seconds']:.1f}" for k, v in ph.items()
                  if v["wall_seconds"] >= 0.05 or v["cpu_seconds"] >= 0.05)
print(f"{b:<4} {j:<3} {cpu:9.2f} {rss:9.1f} {wall:8.1f}  {phases}")
open(out + ".cpu", "w").write(f"{cpu}\n")
EOF
  done
done

first=${threads%% *}
for b in "${!binaries[@]}"; do
  line="bin $b (${binaries[$b]}): CPU over -j $first:"
  base=$(cat "$dir/b$b-j$first.cpu")
  for j in $threads; do
    line+=" -j $j $(python3 -c "print(f'{$(cat "$dir/b$b-j$j.cpu") / $base:.3f}')")"
  done
  echo "$line"
done
same=yes
for f in "$dir"/b*-j*.pvs; do cmp -s "$f" "$dir/b0-j$first.pvs" || same=no; done
echo "every file byte-identical: $same"
[ "${KEEP:-0}" = 1 ] || rm -rf "$dir"
