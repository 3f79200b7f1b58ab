#!/usr/bin/env bash
# make jitter: wake-up latency of irdm-fw's force loop against cyclictest's,
# on the same CPU, at the same SCHED_FIFO priority and interval, one after
# the other, JITTER_SECONDS each (default 60).
#   tools/scripts/jitter.sh IRDM IRDM_FW IMAGE
# irdm-fw runs the simulated board in real time with the press-hold-release
# hand (free ticks after it: the proxy's query is their cost), logging every
# tick; cyclictest measures the kernel's own wake-up latency.  This host's
# kernel may not be PREEMPT_RT (the first line of irdm-fw says): maxima then
# include its preemptions, for both.
set -euo pipefail
irdm=$1; fw=$2; image=$3
secs=${JITTER_SECONDS:-60}
# The simulated board, pinned to one CPU, with overruns counted rather than
# faulting (K = 1000, a 1 s watchdog): on a host that is not real time the
# measurement must reach its end; the safety policy itself is tested in
# tests/test_controller.c and tests/test_safety.c.
cpu=$(( $(nproc) > 1 ? 1 : 0 ))
mkdir -p out
board=out/jitter.board
sed -e "s/^cpu *=.*/cpu = $cpu/" -e 's/^overrun_fault_count *=.*/overrun_fault_count = 1000/' \
	-e 's/^watchdog_us *=.*/watchdog_us = 1000000/' \
	boards/sim-phantom.board > $board
key() { awk -F= -v k="$1" '$1 ~ "^"k" *$" { sub(/#.*/, "", $2); gsub(/ /, "", $2); print $2 }' $board; }
prio=$(key force_priority); period=$(key period_us)
prio=${prio:-80}; period=${period:-1000}
if ! command -v cyclictest >/dev/null; then
	echo "jitter: cyclictest not installed (Debian package rt-tests)" >&2
	exit 1
fi

echo "jitter: irdm-fw for ${secs} s (SCHED_FIFO ${prio}, ${period} us, CPU ${cpu})"
"$fw" --board $board --image "$image" --user scenes/users/press-hold-release.user \
	--clock real --duration "$secs" --log out/jitter.log | tee out/jitter-fw.txt
"$irdm" log export out/jitter.log -o out/jitter.csv

echo "jitter: cyclictest for ${secs} s (SCHED_FIFO ${prio}, ${period} us, CPU ${cpu})"
loops=$(( secs * 1000000 / period ))
cyclictest -m -q -p "$prio" -i "$period" -a "$cpu" -t 1 -l "$loops" -h 100000 \
	> out/jitter-cyclictest.txt

# percentiles (nearest rank) of the wake-up latency, us: irdm-fw's from its
# per-tick log, cyclictest's from its 1 us histogram
/usr/bin/python3 - out/jitter.csv out/jitter-cyclictest.txt <<'PY'
import csv, math, sys

def ranks(sorted_v):
    def q(p):
        return sorted_v[max(0, math.ceil(p * len(sorted_v)) - 1)]
    return q(0.50), q(0.99), q(0.999), sorted_v[-1]

with open(sys.argv[1], newline="") as f:
    rows = csv.DictReader(f)
    fw, comp = [], []
    for r in rows:
        fw.append(int(r["wake_latency_ns"]) / 1000.0)
        comp.append(int(r["compute_ns"]) / 1000.0)
fw.sort(); comp.sort()
ct = []
for line in open(sys.argv[2]):
    if line.startswith("#") or not line.strip():
        continue
    us, *counts = line.split()
    if not us.isdigit():
        continue
    ct.extend([float(us)] * sum(int(c) for c in counts))
ct.sort()
if not fw or not ct:
    sys.exit("jitter: no samples")
f, c, k = ranks(fw), ranks(ct), ranks(comp)
print(f"{'wake-up latency (us)':24s} {'p50':>9s} {'p99':>9s} {'p99.9':>9s} {'max':>9s}  samples")
print(f"{'irdm-fw':24s} {f[0]:9.1f} {f[1]:9.1f} {f[2]:9.1f} {f[3]:9.1f}  {len(fw)}")
print(f"{'cyclictest':24s} {c[0]:9.1f} {c[1]:9.1f} {c[2]:9.1f} {c[3]:9.1f}  {len(ct)}")
r = [a / b if b > 0 else float('inf') for a, b in zip(f, c)]
print(f"{'ratio irdm-fw/cyclictest':24s} {r[0]:9.2f} {r[1]:9.2f} {r[2]:9.2f} {r[3]:9.2f}")
print(f"{'irdm-fw compute (us)':24s} {k[0]:9.1f} {k[1]:9.1f} {k[2]:9.1f} {k[3]:9.1f}")
over = sum(1 for x in comp if x > 1000.0)
print(f"overruns (compute > period): {over}")
print(f"jitter: p99 ratio {r[1]:.2f}, max ratio {r[3]:.2f} (irdm-fw / cyclictest)")
PY
