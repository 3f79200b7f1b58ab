#!/usr/bin/env bash
# make jitter: wake-up latency of irdm-fw's force loop against cyclictest's,
# on the same CPU, at the same SCHED_FIFO priority and interval, alternating
# in short rounds (JITTER_ROUNDS rounds of JITTER_SECONDS each, default
# 10 x 3 s; the order swaps every round), so that a load that changes
# during the measurement falls on both tools alike.
#   tools/scripts/jitter.sh IRDM IRDM_FW IMAGE
# irdm-fw's wake-ups are counted as cyclictest counts its own: the ticks run
# late after a stall (catch-up ticks, which did not sleep) are left out and
# counted apart, as cyclictest skips the periods a late wake-up missed.
# Prints each round's p50, p99 and max of both, the pooled percentiles, the
# ratio of the pooled p50 and p99 (irdm-fw / cyclictest) and its spread over
# the rounds (min..max of the per-round ratio); writes the same, with the
# host's conditions, to docs/measurements/jitter.md (JITTER_DOC: elsewhere).
# JITTER_BASELINE=PATH adds another irdm-fw binary to every round (a
# before/after of a change to the loop, in one run).
# irdm-fw runs the simulated board in real time with the press-hold-release
# hand, logging every tick (its wake_latency_ns column); cyclictest
# measures the kernel's own wake-up latency (its 1 us histogram).  This
# host's kernel may not be PREEMPT_RT (irdm-fw's first line says): maxima
# then include its preemptions, for both.
set -euo pipefail
irdm=$1; fw=$2; image=$3
secs=${JITTER_SECONDS:-3}
rounds=${JITTER_ROUNDS:-10}
baseline=${JITTER_BASELINE:-}
doc=${JITTER_DOC:-docs/measurements/jitter.md}
command_line="make jitter JITTER_ROUNDS=$rounds JITTER_SECONDS=$secs${baseline:+ JITTER_BASELINE=$baseline}"
# The simulated board, pinned to one CPU, with overruns counted rather than
# faulting (K = 1000, a 1 s watchdog): on a host that is not real time the
# measurement must reach its end; the safety policy itself is tested in
# tests/test_controller.c and tests/test_safety.c.
cpu=$(( $(nproc) > 1 ? 1 : 0 ))
out=out/jitter
rm -rf "$out"
mkdir -p "$out"
board=$out/jitter.board
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
[ -z "$baseline" ] || [ -x "$baseline" ] || { echo "jitter: no program $baseline" >&2; exit 1; }
loops=$(( secs * 1000000 / period ))

# The conditions a figure from this host needs beside it.
host_header() {   # host_header LOAD_BEFORE LOAD_AFTER
	local model
	model=$(awk -F': ' '/^model name/ { print $2; exit }' /proc/cpuinfo)
	echo "- command: \`$command_line\`"
	echo "- date: $(date -u '+%Y-%m-%d %H:%M:%S UTC')"
	echo "- CPU: ${model:-unknown}, $(nproc) cores online"
	echo "- kernel: $(uname -r) ($(uname -v | grep -q PREEMPT_RT && echo PREEMPT_RT || echo not PREEMPT_RT))"
	echo "- load average (1, 5, 15 min) before: $1; after: $2"
}

run_fw() {   # run_fw NAME PROGRAM ROUND
	"$2" --board $board --image "$image" --user scenes/users/press-hold-release.user \
		--clock real --duration "$secs" --log "$out/$1-$3.log" > "$out/$1-$3.txt"
	"$irdm" log export "$out/$1-$3.log" -o "$out/$1-$3.csv"
}

run_cyclictest() {   # run_cyclictest ROUND
	cyclictest -m -q -p "$prio" -i "$period" -a "$cpu" -t 1 -l "$loops" -h 100000 \
		> "$out/cyclictest-$1.txt"
}

load_before=$(cut -d' ' -f1-3 /proc/loadavg)
echo "jitter: $rounds rounds of ${secs} s each, irdm-fw and cyclictest alternating" \
	"(SCHED_FIFO $prio, $period us, CPU $cpu)"
for r in $(seq 1 "$rounds"); do
	echo "jitter: round $r of $rounds"
	# the order swaps every round: neither tool always follows the other
	if (( r % 2 )); then
		run_fw irdm-fw "$fw" "$r"
		[ -z "$baseline" ] || run_fw baseline "$baseline" "$r"
		run_cyclictest "$r"
	else
		run_cyclictest "$r"
		[ -z "$baseline" ] || run_fw baseline "$baseline" "$r"
		run_fw irdm-fw "$fw" "$r"
	fi
done
load_after=$(cut -d' ' -f1-3 /proc/loadavg)
grep -E '^(real-time|idle states|thread)' "$out/irdm-fw-1.txt" || true

mkdir -p "$(dirname "$doc")"
{
	echo "# irdm-fw's wake-up latency beside cyclictest's"
	echo
	echo "Written by \`make jitter\` (tools/scripts/jitter.sh): irdm-fw (the simulated"
	echo "board, the press-hold-release hand, the deformation worker at 100 Hz, every"
	echo "tick logged) and cyclictest, both SCHED_FIFO $prio on CPU $cpu at $period us,"
	echo "alternating in $rounds rounds of $secs s each (the order swaps every round)."
	echo "Wake-up latency: how late each wait returned after its period's start."
	echo
	host_header "$load_before" "$load_after"
	echo
} > "$out/jitter.md"
/usr/bin/python3 - "$out" "$rounds" "$period" "${baseline:+baseline}" >> "$out/jitter.md" <<'PY'
import csv, math, sys

out, rounds, period_us, baseline = sys.argv[1], int(sys.argv[2]), float(sys.argv[3]), sys.argv[4]

def q(v, p):
    """nearest rank"""
    return v[max(0, math.ceil(p * len(v)) - 1)]

def fw_lat(path):
    """irdm-fw's wake-ups, counted as cyclictest counts its own: a tick whose
    period had begun before the previous tick ended did not sleep (the loop
    runs every period, late), while cyclictest skips to the next period
    boundary after a late wake; so one stall of D is one sample in
    cyclictest and D / period samples in irdm-fw's log.  Those catch-up
    ticks are left out here and counted apart."""
    slept, catch_up, prev_end = [], 0, 0.0
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            lat = int(r["wake_latency_ns"]) / 1000.0
            if prev_end >= period_us:
                catch_up += 1
            else:
                slept.append(lat)
            prev_end = lat + int(r["compute_ns"]) / 1000.0
    return sorted(slept), catch_up

def ct_lat(path):
    v, over = [], 0
    for line in open(path):
        if line.startswith("# Histogram Overflows"):
            over = sum(int(x) for x in line.split(":")[1].split())
        if line.startswith("#") or not line.strip():
            continue
        us, *counts = line.split()
        if us.isdigit():
            v.extend([float(us)] * sum(int(c) for c in counts))
    # beyond the histogram's 100 ms: counted at its end
    v.extend([100000.0] * over)
    return sorted(v), 0

names = ["irdm-fw"] + (["baseline"] if baseline else []) + ["cyclictest"]
per, skipped = {}, {}
for n in names:
    runs = [ct_lat(f"{out}/cyclictest-{r}.txt") if n == "cyclictest"
            else fw_lat(f"{out}/{n}-{r}.csv") for r in range(1, rounds + 1)]
    per[n] = [v for v, _ in runs]
    skipped[n] = [c for _, c in runs]
    if any(not v for v in per[n]):
        sys.exit(f"jitter: {n}: a round without samples")
fws = names[:-1]
ct = per["cyclictest"]

def ratio(n, i, p):
    return q(per[n][i], p) / max(q(ct[i], p), 1)

print("## Each round (us)\n")
print("| round |" + "".join(f" {n} p50 | {n} p99 | {n} max |" for n in names) +
      "".join(f" {n} catch-up ticks |" for n in fws) + " p50 ratio | p99 ratio |")
print("|---" * (1 + 3 * len(names) + len(fws) + 2) + "|")
for i in range(rounds):
    row = f"| {i + 1} |"
    for n in names:
        v = per[n][i]
        row += f" {q(v, .5):.1f} | {q(v, .99):.1f} | {v[-1]:.1f} |"
    row += "".join(f" {skipped[n][i]} |" for n in fws)
    print(row + f" {ratio('irdm-fw', i, .5):.2f} | {ratio('irdm-fw', i, .99):.2f} |")

print("\n## Pooled over the rounds (us)\n")
print("| | p50 | p99 | p99.9 | max | samples | catch-up ticks left out |")
print("|---|---|---|---|---|---|---|")
pooled = {n: sorted(x for v in per[n] for x in v) for n in names}
for n in names:
    v = pooled[n]
    print(f"| {n} | {q(v, .5):.1f} | {q(v, .99):.1f} | {q(v, .999):.1f} | {v[-1]:.1f} | "
          f"{len(v)} | {sum(skipped[n])} |")

print("\n## Ratio to cyclictest\n")
print("| | pooled p50 | pooled p99 | p50 per round, min..max | p99 per round, min..max |")
print("|---|---|---|---|---|")
c = pooled["cyclictest"]
for n in fws:
    v = pooled[n]
    r50 = [ratio(n, i, .5) for i in range(rounds)]
    r99 = [ratio(n, i, .99) for i in range(rounds)]
    print(f"| {n} / cyclictest | {q(v, .5) / max(q(c, .5), 1):.2f} | "
          f"{q(v, .99) / max(q(c, .99), 1):.2f} | {min(r50):.2f}..{max(r50):.2f} | "
          f"{min(r99):.2f}..{max(r99):.2f} |")
print(f"""
irdm-fw's samples are its wake-ups as cyclictest counts its own: after a
late tick, cyclictest skips to the next period boundary, while irdm-fw runs
every period, late (a tick whose period began before the previous tick
ended, at wake-up latency + compute >= {period_us:.0f} us, did not sleep: a
catch-up tick, left out and counted).  irdm-fw's own summary counts every
tick.  Ratios divide by at least 1 us; percentiles are nearest-rank;
cyclictest's come from its 1 us histogram.""")
PY
cat "$out/jitter.md"
cp "$out/jitter.md" "$doc"
echo "jitter: written to $doc"
