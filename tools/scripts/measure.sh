#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Runs a measurement and writes its figures to docs/measurements/NAME.md
# with what they depend on: the command, the date (UTC), the machine (CPU
# model, cores, kernel) and the load average before and after.  A figure in
# the documentation links to such a file instead of copying it, so the
# numbers and their conditions are rewritten together.
#
#   tools/scripts/measure.sh [-m] [-f BODY] NAME 'COMMAND AS TYPED' -- CMD [ARG]...
#
# CMD's standard output goes to the terminal and, unless -f is given, into
# the file as a preformatted block (-m: it is Markdown already, written as
# is).  -f BODY: the file's body is BODY, a file CMD writes (the terminal
# keeps CMD's output).  The file is replaced only when CMD succeeds.
# MEASURE_DIR (default docs/measurements) says where.
set -euo pipefail
md=0 body=
while getopts mf: o; do
	case $o in
	m) md=1 ;;
	f) body=$OPTARG; md=1 ;;
	*) exit 2 ;;
	esac
done
shift $((OPTIND - 1))
[ $# -ge 3 ] && [ "$3" = "--" ] || {
	echo "usage: measure.sh [-m] [-f BODY] NAME 'COMMAND' -- CMD [ARG]..." >&2
	exit 2
}
name=$1 typed=$2
shift 3
# make -n runs a recipe line that calls $(MAKE) (ours run the measurement
# through a sub-make): then only the sub-make's dry run, and no file.
flags=${MAKEFLAGS:-}
flags=${flags%% *}
case $flags in -*) flags= ;; esac
case $flags in
*n*) exec "$@" ;;
esac
dir=${MEASURE_DIR:-docs/measurements}
mkdir -p "$dir"
out=$dir/$name.md
tmp=$(mktemp "$dir/.$name.XXXXXX")
trap 'rm -f "$tmp" "$tmp.out"' EXIT

load() { cut -d' ' -f1-3 /proc/loadavg; }
cpu=$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -n 1)
load0=$(load)
date0=$(date -u '+%Y-%m-%d %H:%M')

"$@" | tee "$tmp.out"

{
	echo "# Measurement: $name"
	echo
	echo "Written by \`$typed\`, which rewrites this file; do not edit it by hand."
	echo
	echo "- date (UTC): $date0 to $(date -u '+%H:%M')"
	echo "- machine: ${cpu:-unknown CPU}, $(nproc) cores, Linux $(uname -r)"
	echo "- load average (1, 5, 15 min): $load0 at the start, $(load) at the end"
	echo
	if [ -n "$body" ]; then
		cat "$body"
	elif [ "$md" = 1 ]; then
		cat "$tmp.out"
	else
		echo '```'
		cat "$tmp.out"
		echo '```'
	fi
} > "$tmp"
mv "$tmp" "$out"
echo "measure: $out"
