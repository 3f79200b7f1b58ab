#!/usr/bin/env bash
# Fetch the Stanford bunny from the npm registry (package `bunny`: positions
# and triangle cells) and write it as an OFF surface, scaled to 20 cm tall
# (the paper's bunny) with its base at z = 0 and z up (the file is y up).
#   tools/scripts/bunny-off.sh OUT.off
set -euo pipefail
out=${1:?usage: bunny-off.sh OUT.off}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
( cd "$work" && npm pack --silent bunny@1.0.1 >/dev/null 2>&1 ) || { echo "bunny-off.sh: cannot fetch npm package 'bunny'" >&2; exit 1; }
tar -xzf "$work"/bunny-1.0.1.tgz -C "$work"
node -e '
const b = require(process.argv[1] + "/package/index.js");
const p = b.positions, c = b.cells;
let lo = Infinity, hi = -Infinity;
for (const v of p) { lo = Math.min(lo, v[1]); hi = Math.max(hi, v[1]); }
const s = 0.2 / (hi - lo);
const lines = ["OFF", p.length + " " + c.length + " 0"];
/* (x, y, z) y-up -> (x, -z, y) z-up keeps the orientation right-handed */
for (const v of p) lines.push([v[0] * s, -v[2] * s, (v[1] - lo) * s].map(x => x.toPrecision(9)).join(" "));
for (const f of c) lines.push("3 " + f.join(" "));
process.stdout.write(lines.join("\n") + "\n");
' "$work" > "$out.tmp"
mv "$out.tmp" "$out"
echo "bunny-off.sh: wrote $out"
