#!/bin/sh
# The HIL scenarios, run inside the VM by /init (busybox sh; vcan0 is up).
# Each: candump logs the bus (a 4 MB receive buffer: the flood overran its
# default one), irdm-candrives emulates the drives (the
# press-hold-release hand pushing its arm; the scenario's faults), irdm-fw
# runs the board in real time; their outputs, exit codes and logs go to
# /out/NAME.* for the host's checks (hil-check.py).
H=/hil
B=$H/can-3dof-vm.board
. $H/params.sh          # FAULT_AT: the SYNC of 1.5 s, mid-hold (the press ends at 1.2 s);
			# TPDO_MISSING: the board's tpdo_missing_periods; KILL_WAIT:
			# seconds to watch the drives after irdm-fw is killed

echo "hil-guest: SocketCAN port tests on vcan0"
IRDM_SOCKETCAN_TEST_IF=vcan0 $H/test_socketcan > /out/test_socketcan.txt 2>&1
echo $? > /out/test_socketcan.rc
tail -n 3 /out/test_socketcan.txt

# scenario NAME SECONDS [FAULT...]
scenario() {
	name=$1 secs=$2
	shift 2
	faults=""
	for f in "$@"; do faults="$faults --fault $f"; done
	echo "hil-guest: scenario $name ($secs s of irdm-fw${faults:+,$faults})"
	candump -r 4194304 -L vcan0 > /out/$name.candump 2>/dev/null &
	dump=$!
	$H/irdm-candrives --board $B --if vcan0 --user $H/press-hold-release.user $faults \
		> /out/$name.cd.txt 2>&1 &
	drives=$!
	sleep 0.3
	timeout 120 $H/irdm-fw --board $B --image $H/default.img --duration $secs \
		--log /out/$name.log > /out/$name.fw.txt 2>&1
	echo $? > /out/$name.fw.rc
	sleep 0.2
	kill -TERM $drives 2>/dev/null
	wait $drives
	echo $? > /out/$name.cd.rc
	kill -TERM $dump 2>/dev/null
	wait $dump 2>/dev/null
	tail -n 2 /out/$name.fw.txt
}

# irdm-fw killed with SIGKILL mid-run, nothing caught: the drives must stop
# by themselves within their deadline (candump shows their EMCYs)
scenario_kill() {
	echo "hil-guest: scenario kill (irdm-fw killed with SIGKILL 3 s after its start)"
	candump -r 4194304 -L vcan0 > /out/kill.candump 2>/dev/null &
	dump=$!
	$H/irdm-candrives --board $B --if vcan0 --user $H/press-hold-release.user \
		> /out/kill.cd.txt 2>&1 &
	drives=$!
	sleep 0.3
	$H/irdm-fw --board $B --image $H/default.img --duration 4 > /out/kill.fw.txt 2>&1 &
	fw=$!
	sleep 3         # the set-up (1.0-1.3 s under TCG), then the hold (1.2-3.2 s of the run)
	kill -KILL $fw
	wait $fw
	echo $? > /out/kill.fw.rc
	sleep $KILL_WAIT
	kill -TERM $drives 2>/dev/null
	wait $drives
	echo $? > /out/kill.cd.rc
	kill -TERM $dump 2>/dev/null
	wait $dump 2>/dev/null
}

# TCG translates guest code on its first execution (a first tick there
# stalls ~100 ms, and the clock's catch-up ticks then read before the
# drives could answer); a first run warms its cache, its result is kept
# but not judged
scenario warmup 4
scenario base 4
B=$H/can-3dof-vm-nocounter.board
scenario nocounter 2.5
B=$H/can-3dof-vm.board
scenario_kill
# the heartbeat is lost 200 periods after it stops (at 1.5 s): a longer run
scenario heartbeat 4.5 heartbeat-stop:2:$FAULT_AT
scenario emcy 2.5 emcy:3:$FAULT_AT:0x2310
scenario fault 2.5 fault:1:$FAULT_AT
scenario drop 2.5 drop:2:$FAULT_AT:$((TPDO_MISSING + 5))
scenario drop-short 2.5 drop:2:$FAULT_AT:$((TPDO_MISSING / 2))
scenario delay 2.5 delay:2:$FAULT_AT:5:30000
scenario flood 2.5 flood:$FAULT_AT:1000
scenario sdo 2.5 sdo-wrong:2
# bus-off: the interface goes away under both ends 3 s after the start
# (the set-up takes 1.0-1.3 s under TCG: mid-run)
( sleep 3; ip link set vcan0 down; echo "hil-guest: vcan0 down" ) &
scenario busoff 2.5
ip link set vcan0 up
