#!/usr/bin/env bash
# Every malformed or contradictory scene of tests/scenes/bad through the command line:
# exit 4 (invalid scene; 3 where the file itself cannot be read as a scene), one
# line on stderr naming the file and the key, and an output folder that already holds a
# run left exactly as it was (test_scene checks each message's line, key and reason).
set -uo pipefail
RHOD=$1; SRC=$2
# shellcheck source=lib_cli.sh
source "$(dirname "$0")/lib_cli.sh"
# a previous run's folder, to be left alone by every failing run
"$RHOD" run "$SRC/tests/scenes/run/periodic_uniform.yaml" -o "$T/out" >/dev/null 2>&1 ||
  { echo "FAIL: setting up the previous run"; exit 1; }
(cd "$T/out" && find . -type f -exec sha256sum {} + | sort) >"$T/before"
n=0
for scene in "$SRC"/tests/scenes/bad/*.yaml; do
  name=$(basename "$scene")
  n=$((n + 1))
  "$RHOD" run "$scene" -o "$T/out" >"$T/stdout" 2>"$T/stderr"
  code=$?
  lines=$(wc -l <"$T/stderr")
  if [ $code -ne 4 ] && [ $code -ne 3 ]; then
    echo "FAIL: $name: exit $code, expected 4 (invalid scene) or 3 (unreadable)"; fail=$((fail + 1))
  elif [ "$lines" -ne 1 ] || ! grep -q "$name" "$T/stderr"; then
    echo "FAIL: $name: not one line naming the file:"; cat "$T/stderr"; fail=$((fail + 1))
  elif [ -s "$T/stdout" ]; then
    echo "FAIL: $name: wrote to stdout"; fail=$((fail + 1))
  else
    pass=$((pass + 1))
  fi
done
# the multiphase scheme's keys and moving walls given by --set: one line naming the override
# and the key
MP=$SRC/tests/scenes/good/multiphase_minimal.yaml
while IFS='|' read -r set key reason; do
  n=$((n + 1))
  "$RHOD" run "$MP" --set "$set" -o "$T/out" >"$T/stdout" 2>"$T/stderr"
  code=$?
  if [ $code -ne 4 ] || [ "$(wc -l <"$T/stderr")" -ne 1 ] ||
    ! grep -qF -- "--set $set: $key: $reason" "$T/stderr"; then
    echo "FAIL: --set $set: exit $code:"; cat "$T/stderr"; fail=$((fail + 1))
  else
    pass=$((pass + 1))
  fi
done <<'EOF_SETS'
fluid.0.phase=oil|fluid.0.phase|unknown phase 'oil'
phases.0.gamma=0|phases.0.gamma|must be > 0
multiphase.sigma=-1|multiphase.sigma|must be >= 0
multiphase.sigma=0.07|multiphase.sigma|a surface tension needs at least two phases
phases.1={name: water, rho0: 1, c: 1}|phases.1.name|duplicate phase name 'water'
multiphase.sigma_pairs.0={phases: [water, water], sigma: 1}|multiphase.sigma_pairs|a surface tension needs at least two phases
fluid.1={rect: {min: [0, 0], max: [1, 0.5]}}|fluid.1|no phase
physics.c0=20|physics.c0|belongs to the rhodsph scheme
walls.0={circle: {center: [0, 0], radius: 2}, velocity: [1, 0]}|walls.0.velocity|a circle wall cannot move
walls.0={rect: {min: [0, 0], max: [1, 1]}, velocity: [0, 1], edges: [0]}|walls.0.velocity|[0, 1] is not along edge 0
walls.0={rect: {min: [0, 0], max: [1, 1]}, velocity: [0, 1], edges: [4]}|walls.0.edges.0|edge 4 out of range
EOF_SETS
(cd "$T/out" && find . -type f -exec sha256sum {} + | sort) >"$T/after"
if cmp -s "$T/before" "$T/after"; then pass=$((pass + 1)); else
  echo "FAIL: a failing run changed the output folder"; diff "$T/before" "$T/after" | head; fail=$((fail + 1))
fi
[ $n -ge 30 ] || { echo "FAIL: only $n bad scenes (30 wanted)"; fail=$((fail + 1)); }
summary "$n bad scenes"
