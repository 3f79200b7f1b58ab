#!/usr/bin/env bash
# make jitter-view: does a browser watching the live view (irdm-fw --view)
# move the force loop's timing?  JITTER_ROUNDS pairs of irdm-fw runs in real
# time, JITTER_SECONDS each, alternating without and with the view and a
# headless Chromium on its page, on the board make jitter uses (pinned to
# one CPU, overruns counted rather than faulting); then the wake-up latency
# and compute-time percentiles of every run from its log, the spread of the
# runs without the browser, and whether the runs with it stay inside.
#   tools/scripts/jitter-view.sh IRDM IRDM_FW IMAGE
set -euo pipefail
irdm=$1; fw=$2; image=$3
secs=${JITTER_SECONDS:-20}
rounds=${JITTER_ROUNDS:-3}
browser=${IRDM_CHROMIUM:-/usr/bin/chromium}
[ -x "$browser" ] || { echo "jitter-view: no $browser (Debian package chromium)" >&2; exit 1; }
cpu=$(( $(nproc) > 1 ? 1 : 0 ))
out=out/jitter-view
rm -rf "$out"
mkdir -p "$out"
board=$out/jitter.board
sed -e "s/^cpu *=.*/cpu = $cpu/" -e 's/^overrun_fault_count *=.*/overrun_fault_count = 1000/' \
	-e 's/^watchdog_us *=.*/watchdog_us = 1000000/' \
	boards/sim-phantom.board > $board

browser_pid=
stop_browser() {
	if [ -n "$browser_pid" ]; then
		kill -- -"$browser_pid" 2>/dev/null || true
		wait "$browser_pid" 2>/dev/null || true
		browser_pid=
	fi
}
trap stop_browser EXIT

run() {   # run NAME [--view 0]
	local name=$1; shift
	echo "jitter-view: $name for ${secs} s"
	"$fw" --board $board --image "$image" --user scenes/users/press-hold-release.user \
		--clock real --duration "$secs" --log "$out/$name.log" "$@" > "$out/$name.txt" &
	local pid=$!
	if [ $# -gt 0 ]; then
		local port=
		for _ in $(seq 100); do
			port=$(sed -n 's|^view: http://127.0.0.1:\([0-9]*\)/$|\1|p' "$out/$name.txt")
			[ -n "$port" ] && break
			sleep 0.1
		done
		[ -n "$port" ] || { echo "jitter-view: the view did not start" >&2; exit 1; }
		# its own process group, so that the whole browser goes with it
		setsid "$browser" --headless --no-sandbox --user-data-dir="$out/profile" \
			--window-size=1000,600 "http://127.0.0.1:$port/" > "$out/$name-chromium.log" 2>&1 &
		browser_pid=$!
	fi
	wait $pid
	stop_browser
	# the log's blocks and checksums are read by irdm (docs/log-format.md)
	"$irdm" log export "$out/$name.log" -o "$out/$name.csv"
	grep -E '^view: [0-9]' "$out/$name.txt" || true
}

for r in $(seq "$rounds"); do
	run "plain-$r"
	run "browser-$r" --view 0
done

/usr/bin/python3 - "$out" "$rounds" <<'PY'
import csv, math, sys

out, rounds = sys.argv[1], int(sys.argv[2])

def load(path):
    lat, comp = [], []
    with open(path, newline='') as f:
        for r in csv.DictReader(f):
            lat.append(int(r['wake_latency_ns']) / 1000.0)
            comp.append(int(r['compute_ns']) / 1000.0)
    return sorted(lat), sorted(comp)

def pct(v):
    q = lambda p: v[max(0, math.ceil(p * len(v)) - 1)]
    return [q(0.5), q(0.99), q(0.999), v[-1]]

rows = {}
for kind in ('plain', 'browser'):
    for r in range(1, rounds + 1):
        lat, comp = load(f'{out}/{kind}-{r}.csv')
        rows[(kind, r)] = (pct(lat), pct(comp), sum(1 for x in comp if x > 1000.0), len(lat))
names = ['p50', 'p99', 'p99.9', 'max']
print(f"{'run':12s} | wake-up latency (us) {'':8s}| compute (us) {'':16s}| overruns  ticks")
print(f"{'':12s} | " + ' '.join(f'{n:>7s}' for n in names) + ' | ' +
      ' '.join(f'{n:>7s}' for n in names) + ' |')
for r in range(1, rounds + 1):
    for kind in ('plain', 'browser'):
        l, c, o, n = rows[(kind, r)]
        print(f'{kind + "-" + str(r):12s} | ' + ' '.join(f'{x:7.1f}' for x in l) + ' | ' +
              ' '.join(f'{x:7.1f}' for x in c) + f' | {o:8d} {n:6d}')
inside = True
for i, what in ((0, 'latency'), (1, 'compute')):
    for k, n in enumerate(names[:3]):
        plain = [rows[('plain', r)][i][k] for r in range(1, rounds + 1)]
        br = [rows[('browser', r)][i][k] for r in range(1, rounds + 1)]
        lo, hi = min(plain), max(plain)
        # a browser can only make the loop worse: above the slowest run
        # without it is a change beyond the spread
        ok = max(br) <= hi
        inside &= ok
        print(f'jitter-view: {what} {n}: without the browser {lo:.1f}..{hi:.1f} us, with it '
              f'{min(br):.1f}..{max(br):.1f} us: {"within the spread" if ok else "ABOVE the spread"}')
over = sum(rows[(k, r)][2] for k in ('plain', 'browser') for r in range(1, rounds + 1))
print(f'jitter-view: overruns {over}; percentiles with the browser '
      f'{"inside" if inside else "outside"} the run-to-run spread (p50, p99, p99.9)')
PY
