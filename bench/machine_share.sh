#!/usr/bin/env bash
# machine_share.sh: how much slower one core's work runs when every core is busy, on this
# machine, with nothing shared between the processes (docs/performance.md, "On 16 cores").
#
#   bench/machine_share.sh K COMMAND...
#
# Runs COMMAND alone, then K copies of it at once, then alone again, and prints each process's
# CPU seconds (user + system, from wait4): alone (both runs), and with K at once (median, least,
# most). In COMMAND, '@' is replaced by the copy's number (0 for the runs alone), so the copies
# can write to files of their own. The share is the K copies' mean CPU seconds over the mean of
# the runs alone; K / share is the speed-up K workers reach with that work on this machine when
# they share nothing but the machine, the reference for a speed-up at -j K. The share is the
# machine's (clock, shared caches, memory bandwidth, on a virtual machine whatever the host
# shares) as the work meets it: work with less memory traffic may lose less. Exits 2 on bad
# usage, 1 when a run fails.
set -euo pipefail
if [ $# -lt 2 ] || ! [[ $1 =~ ^[1-9][0-9]*$ ]]; then
  sed -n '2,14p' "$0"
  exit 2
fi
exec python3 - "$@" <<'EOF'
import os, subprocess, sys, time

k, command = int(sys.argv[1]), sys.argv[2:]


def run(copies):
    """CPU seconds of each of `copies` processes started at once, and the wall seconds."""
    start, running, cpu = time.time(), set(), []
    for i in range(copies):
        args = [a.replace("@", str(i)) for a in command]
        running.add(subprocess.Popen(args).pid)
    while running:
        pid, status, usage = os.wait4(-1, 0)
        if pid not in running:
            continue
        running.remove(pid)
        if status != 0:
            sys.exit(f"machine_share.sh: {' '.join(command)} failed (wait status {status})")
        cpu.append(usage.ru_utime + usage.ru_stime)
    return sorted(cpu), time.time() - start


alone1, _ = run(1)
together, wall = run(k)
alone2, _ = run(1)
alone = (alone1[0] + alone2[0]) / 2
mean = sum(together) / k
share = mean / alone
print(f"alone: {alone1[0]:.2f} and {alone2[0]:.2f} CPU s")
print(f"{k} at once: median {together[k // 2]:.2f}, least {together[0]:.2f}, "
      f"most {together[-1]:.2f} CPU s per copy ({wall:.1f} s wall)")
print(f"share {share:.3f}: {k} workers sharing nothing but the machine reach {k / share:.1f}x")
EOF
