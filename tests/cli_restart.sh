#!/usr/bin/env bash
# Checkpoint and restart (issue 5): a run stopped by SIGTERM, or resumed from a periodic
# checkpoint after a "crash", continues bit for bit (snapshots, pictures, XDMF and
# probes byte-identical to an uninterrupted run); damaged, missing or unfitting
# checkpoints are refused with a one-line message and their own exit code.
set -uo pipefail
RHOD=$1; SRC=$2
# shellcheck source=lib_cli.sh
source "$(dirname "$0")/lib_cli.sh"
same_outputs() { # same_outputs A B: every snapshot, picture, xdmf and probes.csv equal
  local a=$1 b=$2 f n=0
  for f in "$a"/snapshot_*.h5 "$a"/snapshot_*.png "$a"/snapshots.xdmf "$a"/probes.csv; do
    cmp -s "$f" "$b/$(basename "$f")" || { echo "  differs: $(basename "$f")"; return 1; }
    n=$((n + 1))
  done
  [ "$(ls "$b"/snapshot_*.h5 | wc -l)" -eq "$(ls "$a"/snapshot_*.h5 | wc -l)" ] && [ $n -gt 10 ]
}
# the dam break: walls, free surface, shifting, every term; 1250 particles
cp "$SRC/cases/dam_break/scene.yaml" "$T/scene.yaml"
ARGS=(--set particles.dx=0.00584 --set time.end=0.3 --set time.output_every=0.03)

expect 0 "uninterrupted run" -- "$RHOD" run "$T/scene.yaml" -o "$T/a" "${ARGS[@]}" \
  --checkpoint-every 0.1
check "periodic checkpoint written" -- test -s "$T/a/checkpoint.rhod"

# 1. a crash after the checkpoint at t = 0.2: later snapshots gone, probes.csv longer
#    than at the checkpoint (rows after it are cut and written again)
cp -r "$T/a" "$T/b"
rm -f "$T/b"/snapshot_0008.* "$T/b"/snapshot_0009.* "$T/b"/snapshot_0010.*
expect 0 "resume after a crash" -- "$RHOD" resume "$T/b"
check "resumed run identical to the uninterrupted one" -- same_outputs "$T/a" "$T/b"
check "run log says it resumed" -- grep -q "resumed from" "$T/b/run.log"

# 2. SIGTERM in the middle: checkpoint, exit 9 with how to resume, then resume
"$RHOD" run "$T/scene.yaml" -o "$T/c" "${ARGS[@]}" --checkpoint-every 0.02 \
  >"$T/c.out" 2>"$T/c.err" &
pid=$!
for _ in $(seq 1 600); do [ -s "$T/c/checkpoint.rhod" ] && break; sleep 0.02; done
kill -TERM $pid
wait $pid; code=$?
check "SIGTERM: exit 9 (got $code)" -- test $code -eq 9
check "SIGTERM: message says how to resume" -- grep -q "rhod resume" "$T/c.out"
check "SIGTERM: summary says interrupted" -- grep -q '"status": "interrupted"' "$T/c/summary.json"
expect 0 "resume after SIGTERM" -- "$RHOD" resume "$T/c"
check "signal-resumed run identical to the uninterrupted one" -- same_outputs "$T/a" "$T/c"

# 3. APR: two levels split by criterion 3 during the run, and coalesced (the split particles'
#    ids, sizes and masses come back from the checkpoint, the pattern search from the state;
#    the run's totals from RHOD-SPH's named scalars in it: some merges come before the
#    checkpoint at t = 0.2, so a resume that dropped them would report fewer)
APR=(--set particles.dx=0.00584 --set time.end=0.3 --set time.output_every=0.03
  --set refinement.levels=2 --set refinement.free_surface=true --set refinement.coalesce=true
  --set scheme.shifting_a=5 --set scheme.shifting_b=0.5)
expect 0 "APR: uninterrupted run" -- "$RHOD" run "$T/scene.yaml" -o "$T/e" "${APR[@]}" \
  --checkpoint-every 0.1
count() { grep -o "Dimensions=\"[0-9]* 3\"[^>]*>snapshot_$2.h5:/PartType0/Coordinates" \
  "$1/snapshots.xdmf" | grep -o '[0-9][0-9]*' | head -1; }
check "APR: particles were split after the checkpoint" -- \
  test "$(count "$T/e" 0010)" -gt "$(count "$T/e" 0007)"
cp -r "$T/e" "$T/f"
rm -f "$T/f"/snapshot_0008.* "$T/f"/snapshot_0009.* "$T/f"/snapshot_0010.*
expect 0 "APR: resume after a crash" -- "$RHOD" resume "$T/f"
check "APR: resumed run identical to the uninterrupted one" -- same_outputs "$T/e" "$T/f"
totals() {
  grep -E '"(splits|merges|absorbed|merge_dissipation|absorb_dissipation|wall_reflections)"' \
    "$1/summary.json"
}
check "APR: the run split particles" -- grep -q '"splits": [1-9]' "$T/e/summary.json"
check "APR: the run merged and absorbed particles" -- \
  grep -qE '"merges": [1-9].*"absorbed": [1-9]' <(tr -d '\n' <"$T/e/summary.json")
check "APR: split, merge, absorption, dissipation and reflection totals carried over the restart" \
  -- test "$(totals "$T/e")" = "$(totals "$T/f")"

# 5. the multiphase scheme (paper 000): a liquid square relaxing under surface tension in a
#    periodic gas, two phases, the colour pass, the midpoint integrator; the time step's
#    force limit (paper 001 Eq. 15) comes from the last step's accelerations, which the
#    checkpoint carries as a named scalar
cat >"$T/mp.yaml" <<'YAML'
name: mp_restart
scheme: {name: multiphase}
time: {end: 0.05, output_every: 0.005}
particles: {dx: 0.04, jitter: 0.1}
phases:
  - {name: liquid, rho0: 1, c: 10, mu: 0.05}
  - {name: gas, rho0: 0.5, c: 10, mu: 0.05, gamma: 1}
multiphase: {sigma: 1, cfl_force: 0.01} # the force limit (Eq. 15) sets dt
domain: {min: [0, 0], max: [1, 1], periodic: [true, true]}
fluid:
  - rect: {min: [0.3, 0.3], max: [0.7, 0.7]}
    phase: liquid
  - rect: {min: [0, 0], max: [1, 1]}
    phase: gas
probes:
  every: 0.001
  list: [kinetic_energy: {name: ke}, mass: {}]
output:
  picture: {field: phase, width: 200}
YAML
expect 0 "multiphase: uninterrupted run" -- "$RHOD" run "$T/mp.yaml" -o "$T/m" --checkpoint-every 0.02
cp -r "$T/m" "$T/n"
rm -f "$T/n"/snapshot_0009.* "$T/n"/snapshot_0010.*
expect 0 "multiphase: resume after a crash" -- "$RHOD" resume "$T/n"
check "multiphase: resumed run identical to the uninterrupted one" -- same_outputs "$T/m" "$T/n"
check "multiphase: the snapshots hold the phase" -- \
  grep -q "snapshot_0010.h5:/PartType0/Phase" "$T/n/snapshots.xdmf"

# 6. bodies (issue 51): a free cylinder falling (x and theta locked) and a box moved by a
#    law, in a tank; their motion (q, its rate, the acceleration the ghost pressure uses)
#    comes back from the checkpoint's named scalars
cat >"$T/bodies.yaml" <<'YAML'
name: bodies_restart
time: {end: 0.2, output_every: 0.02}
particles: {dx: 0.01}
physics: {rho0: 1000, c0: 20, gravity: [0, -9.81]}
fluid:
  - rect: {min: [0, 0], max: [0.4, 0.3]}
walls:
  - rect: {min: [0, 0], max: [0.4, 0.5]}
bodies:
  - name: ball
    circle: {center: [0.12, 0.18], radius: 0.04}
    motion: free
    density: 1500
    lock: [x, theta]
  - name: paddle
    rect: {min: [0.26, 0.12], max: [0.32, 0.18]}
    slip: no
    motion: imposed
    law: {y: "0.005*sin(20*t)", theta: "0.1*t^2"}
probes: {every: 0.005, list: [{kinetic_energy: {}}]}
YAML
expect 0 "bodies: uninterrupted run" -- "$RHOD" run "$T/bodies.yaml" -o "$T/p" --checkpoint-every 0.1
check "bodies: the ball fell" -- awk -F, 'NR > 1 { y = $7 } END { exit !(y < 0.17) }' "$T/p/probes.csv"
cp -r "$T/p" "$T/q"
rm -f "$T/q"/snapshot_0008.* "$T/q"/snapshot_0009.* "$T/q"/snapshot_0010.*
expect 0 "bodies: resume after a crash" -- "$RHOD" resume "$T/q"
check "bodies: resumed run identical to the uninterrupted one" -- same_outputs "$T/p" "$T/q"

# 7. open boundaries (issue 52): a channel started from rest by an inflow's law, an
#    outflow at the far end; the particles made and removed, the boundary particles' partial
#    masses and every marker's carried imbalance come back from the checkpoint
cat >"$T/open.yaml" <<'YAML'
name: open_restart
time: {end: 0.4, output_every: 0.05}
particles: {dx: 0.02}
physics: {rho0: 1000, c0: 20}
domain: {min: [0, 0], max: [0.6, 0.2]}
fluid:
  - rect: {min: [0, 0], max: [0.6, 0.2]}
walls:
  - rect: {min: [-0.1, -0.1], max: [0.7, 0]}
    fluid_inside: false
    slip: no
  - rect: {min: [-0.1, 0.2], max: [0.7, 0.3]}
    fluid_inside: false
open_boundaries:
  - {kind: inflow, from: [0, 0], to: [0, 0.2], velocity: "1 - exp(-t/0.1)", profile: parabolic}
  - {kind: outflow, from: [0.6, 0], to: [0.6, 0.2]}
probes: {every: 0.01, list: [{mass: {}}, {kinetic_energy: {}}]}
YAML
expect 0 "open: uninterrupted run" -- "$RHOD" run "$T/open.yaml" -o "$T/r" --checkpoint-every 0.2
check "open: particles were made and removed" -- grep -q "particles made, [1-9][0-9]* removed" "$T/r/run.log"
cp -r "$T/r" "$T/s"
rm -f "$T/s"/snapshot_0006.* "$T/s"/snapshot_0007.* "$T/s"/snapshot_0008.*
expect 0 "open: resume after a crash" -- "$RHOD" resume "$T/s"
check "open: resumed run identical to the uninterrupted one" -- same_outputs "$T/r" "$T/s"
check "open: the same mass balance at the end" -- \
  test "$(grep 'open boundaries' "$T/r/run.log")" = "$(grep 'open boundaries' "$T/s/run.log" | tail -2)"

# 4. bad checkpoints: exit 10, one line naming the file and the reason
cp -r "$T/a" "$T/d"
printf 'X' | dd of="$T/d/checkpoint.rhod" bs=1 seek=5000 conv=notrunc 2>/dev/null
expect 10 "corrupted checkpoint" -- "$RHOD" resume "$T/d"
check "corruption named" -- grep -q "checkpoint.rhod: damaged" "$T/stderr"
check "one line" -- test "$(wc -l <"$T/stderr")" -eq 1
cp "$T/a/checkpoint.rhod" "$T/d/checkpoint.rhod"
truncate -s 3000 "$T/d/checkpoint.rhod"
expect 10 "truncated checkpoint" -- "$RHOD" resume "$T/d"
head -c 100 /dev/urandom >"$T/d/checkpoint.rhod"
expect 10 "not a checkpoint" -- "$RHOD" resume "$T/d"
check "not-a-checkpoint named" -- grep -q "not an rhod checkpoint" "$T/stderr"
rm "$T/d/checkpoint.rhod"
expect 10 "missing checkpoint" -- "$RHOD" resume "$T/d"
expect 2 "resume without a folder" -- "$RHOD" resume
cp "$T/a/checkpoint.rhod" "$T/d/checkpoint.rhod"
sed -i 's/c0: 25 /c0: 30 /' "$T/scene.yaml"
expect 10 "scene changed since the checkpoint" -- "$RHOD" resume "$T/d"
check "changed key named" -- grep -q "scene changed since the checkpoint.*physics.c0" "$T/stderr"
check "refused resume left the outputs alone" -- same_outputs "$T/a" "$T/d"
expect 2 "bad --checkpoint-every" -- "$RHOD" run "$T/scene.yaml" --checkpoint-every -1

summary restart
