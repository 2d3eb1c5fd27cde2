#!/bin/bash
# alternate.sh: compare two builds of kernel_speed_bench on one core, the way docs/performance.md
# measures every kernel change. This host's timings drift by several percent from minute to
# minute, so the two binaries run alternately (A, B, A, B, ...) and each one's minimum kernel
# CPU time per case is printed: the figure that repeats. Run it again with A and B swapped before
# believing a difference of a few percent.
#
#   bench/alternate.sh ROUNDS CASES BIN_A BIN_B
#   bench/alternate.sh 5 city2,city20,pandora ../base/build/bench/kernel_speed_bench build/bench/kernel_speed_bench
#
# Prints "A case seconds" and "B case seconds" lines (kern_cpu of `--reps 1 --cores 1`).
# Check that both give the same results first: `BIN --digest FILE --res 256 --cases ...`, then
# cmp the two files.
set -euo pipefail
if [ $# -ne 4 ]; then
  sed -n '2,13p' "$0" | sed 's/^# \{0,1\}//' >&2
  exit 2
fi
rounds=$1 cases=$2 bin_a=$3 bin_b=$4
for bin in "$bin_a" "$bin_b"; do
  [ -x "$bin" ] || { echo "alternate.sh: $bin is not an executable" >&2; exit 2; }
done
for ((i = 0; i < rounds; ++i)); do
  for which in A B; do
    bin=$bin_a
    [ $which = B ] && bin=$bin_b
    # Columns of kernel_speed_bench: case, cores, kernel_s, cube_ms, ratio, kern_cpu, ...
    "$bin" --reps 1 --cores 1 --cases "$cases" 2>/dev/null |
      awk -v w=$which '$2 == "1" { print w, $1, $6 }'
  done
done | awk '{ k = $1 " " $2; if (!(k in m) || $3 < m[k]) m[k] = $3 }
            END { for (k in m) print k, m[k] }' | sort -k2,2 -k1,1
