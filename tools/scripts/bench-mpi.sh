#!/usr/bin/env bash
# The precompute beyond one machine, measured on this one (make bench-mpi):
# a refined built-in cuboid (RES, default 30,30,110: 106,671 nodes), 300
# modes + static correction, a touchable patch of the top face (TOUCH,
# default 13 x 13 nodes), serially (ARPACK on a CHOLMOD factor) and with
# eigensolver = slepc on np = 1 and 2 ranks.  Each image is verified
# (irdm image verify).  Prints the tool's stage times, the slepc stages
# (assembly, MUMPS factorisation, Krylov-Schur, gather), the peak memory
# of every rank and the load average, and keeps the logs in OUT.  Bounded:
# every run stops after TIMEOUT seconds (default 3600).
#   tools/scripts/bench-mpi.sh [IRDM]
set -euo pipefail
irdm=${1:-build/irdm}
res=${RES:-30,30,110}
touch=${TOUCH:-box:0,0,0.2,0.04,0.04,0.2}
out=${OUT:-out/bench-mpi}
limit=${TIMEOUT:-3600}
mpirun=(mpirun --allow-run-as-root --oversubscribe)
scene=(precompute --mesh cuboid --resolution "$res" --fixed 'z<=0' --touch "$touch"
       --representation modal:300 --max_error none)
mkdir -p "$out"
run() {  # name command...
	local name=$1 log=$out/$1.log
	shift
	echo "== $name (load average $(cut -d' ' -f1-3 /proc/loadavg))"
	if ! timeout "$limit" /usr/bin/time -f "wall %e s, CPU %U s user + %S s sys, largest process %M KiB" \
		"$@" -o "$out/$name.img" >"$log" 2>&1; then
		tail -n 5 "$log"
		echo "$name: failed or stopped after $limit s"
		return 0
	fi
	grep -E '^(mesh|modes|image|time|ranks) |^slepc on|^wall' "$log"
	"$irdm" image verify "$out/$name.img" | tail -n 1
}
run serial "$irdm" "${scene[@]}" --eigensolver lanczos
run slepc-np1 "${mpirun[@]}" -np 1 "$irdm" "${scene[@]}" --eigensolver slepc
run slepc-np2 "${mpirun[@]}" -np 2 "$irdm" "${scene[@]}" --eigensolver slepc
