#!/usr/bin/env bash
# Load-time checks and set-up warnings through the command line: every scene of
# tests/scenes/checks stops with exit 4 and one line FILE:LINE:COL: key: reason before
# anything is written (a previous run's folder stays as it was); a particle count the
# memory cannot hold is refused at once (exit 8) instead of being counted; "no particle
# fits" names the block and why; the set-up warnings (tests/scenes/checks_run) are
# printed; output_every > end writes the two snapshots its warning announces.
set -uo pipefail
RHOD=$1; SRC=$2
# shellcheck source=lib_cli.sh
source "$(dirname "$0")/lib_cli.sh"
RUN=$SRC/tests/scenes/checks_run
"$RHOD" run "$SRC/tests/scenes/run/periodic_uniform.yaml" -o "$T/out" >/dev/null 2>&1 ||
  { echo "FAIL: setting up the previous run"; exit 1; }
snap() { (cd "$T/out" && find . -type f -exec sha256sum {} + | sort); }
snap >"$T/before"
n=0
for scene in "$SRC"/tests/scenes/checks/*.yaml "$RUN"/no_fit_*.yaml; do
  name=$(basename "$scene"); n=$((n + 1))
  expect 4 "$name" -- timeout 30 "$RHOD" run "$scene" -o "$T/out"
  check "$name: one line FILE:LINE:COL: key: reason" -- \
    test "$(wc -l <"$T/stderr")" -eq 1 -a "$(grep -cE "$name:[0-9]+:[0-9]+: [a-z_.0-9]+: " "$T/stderr")" -eq 1
  check "$name: nothing on stdout" -- test ! -s "$T/stdout"
done
snap >"$T/after"
check "the previous run is left as it was" -- cmp -s "$T/before" "$T/after"
[ $n -ge 12 ] || { echo "FAIL: only $n scenes"; fail=$((fail + 1)); }
# the causes of "no particle fits"
expect 4 "no fit: outside" -- "$RHOD" run "$RUN/no_fit_outside.yaml" -o "$T/nofit"
check "no fit: the block, its line and its container" -- grep -q \
  "no_fit_outside.yaml:6:5: fluid.0: no particle fits at dx = 0.01 m: all 100 of its lattice points are left out: 100 outside its container walls.0" "$T/stderr"
expect 4 "no fit: obstacle" -- "$RHOD" run "$RUN/no_fit_obstacle.yaml" -o "$T/nofit"
check "no fit: the obstacle, and the other block" -- grep -q \
  "no_fit_obstacle.yaml:7:5: fluid.0: .* inside the obstacle walls.0; no other block holds one either" "$T/stderr"
check "no fit: no output folder" -- test ! -e "$T/nofit"

# a count the memory cannot hold: refused before the lattice is walked (minutes at 2e9)
mem_kb=$(awk '/MemTotal/ {print $2}' /proc/meminfo)
if [ "$mem_kb" -lt 900000000 ]; then
  start=$(date +%s)
  expect 8 "memory: exit 8" -- timeout 60 "$RHOD" run "$SRC/tests/scenes/run/periodic_uniform.yaml" \
    --set particles.dx=2.3e-5 -o "$T/mem"
  check "memory: at once" -- test $(( $(date +%s) - start )) -lt 30
  check "memory: names particles.dx and the estimate" -- \
    grep -q "particles.dx: 2.3e-05 m makes about 1.89e+09 particles, at least .* GB" "$T/stderr"
  check "memory: nothing written" -- test ! -e "$T/mem"
else
  echo "skipped the memory check: ${mem_kb} kB of memory"
fi

# set-up warnings
expect 0 "warnings: runs" -- "$RHOD" run "$RUN/warnings.yaml" -o "$T/w"
check "warning: fluid left out of its container" -- grep -q \
  "rhod: warning: .*warnings.yaml:7:5: fluid.0: 100 of the 200 particles of its lattice are left out: 100 outside its container walls.0" "$T/stdout"
check "warning: a probe in an obstacle" -- grep -q \
  "rhod: warning: .*probes.list.0.pressure.at: \[0.3, 0.15\] lies behind a wall" "$T/stdout"
check "warning: not the probe above the water" -- bash -c "! grep -q 'probes.list.1' '$T/stdout'"
check "warning: in run.log too" -- grep -q "probe in_obstacle will read 0" "$T/w/run.log"
check "no fall warning inside a tank" -- bash -c "! grep -q 'leave the domain' '$T/stdout'"
expect 0 "falling: runs" -- "$RHOD" run "$RUN/falling.yaml" -o "$T/f"
check "warning: nothing below the fluid" -- grep -q \
  "rhod: warning: .*physics.gravity: 200 of the 200 fluid particles have no wall below them .* will leave the domain" "$T/stdout"

# output_every > end: the two snapshots the warning announces
expect 0 "output_every > end" -- "$RHOD" run "$SRC/tests/scenes/run/periodic_uniform.yaml" \
  --set time.end=0.01 --set time.output_every=1 -o "$T/two"
check "its warning" -- grep -q "two snapshots are written, at t = 0 and at the end" "$T/stdout"
check "and the two snapshots" -- test -f "$T/two/snapshot_0000.h5" -a -f "$T/two/snapshot_0001.h5" \
  -a ! -e "$T/two/snapshot_0002.h5"
summary "scene checks ($n refused scenes)"
