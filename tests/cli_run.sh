#!/usr/bin/env bash
# The rhod command line: output layout, exit codes per class of failure, output
# folder untouched by a run that fails its checks, an unstable run stopped with its
# cause named and no NaN written.
set -uo pipefail
RHOD=$1; SRC=$2
# shellcheck source=lib_cli.sh
source "$(dirname "$0")/lib_cli.sh"
SCENE=$SRC/cases/hydrostatic/scene.yaml
SHORT=(--set particles.dx=0.05 --set time.end=0.1 --set time.output_every=0.05)

# a good run: the whole output layout
expect 0 "short run" -- "$RHOD" run "$SCENE" -o "$T/ok" "${SHORT[@]}"
for f in snapshot_0000.h5 snapshot_0002.h5 snapshot_0000.png snapshots.xdmf probes.csv \
         summary.json run.log; do
  check "output file $f" -- test -s "$T/ok/$f"
done
check "run log says where the kernels ran" -- grep -q "kernels run on" "$T/ok/run.log"
check "summary status ok" -- grep -q '"status": "ok"' "$T/ok/summary.json"
check "probes header starts with t" -- bash -c "head -1 '$T/ok/probes.csv' | grep -q '^t,'"

# usage errors
expect 2 "no arguments" -- "$RHOD"
expect 2 "unknown command" -- "$RHOD" fly "$SCENE"
expect 2 "run without scene" -- "$RHOD" run
expect 2 "unknown option" -- "$RHOD" run "$SCENE" --frobnicate
expect 2 "--set without =" -- "$RHOD" run "$SCENE" --set time.end

# scene errors leave an existing output folder untouched
mkdir -p "$T/keep"; echo precious >"$T/keep/snapshot_0000.h5"
expect 3 "missing scene file" -- "$RHOD" run "$T/nope.yaml" -o "$T/keep"
check "message names the file" -- grep -q "nope.yaml" "$T/stderr"
expect 4 "bad override value" -- "$RHOD" run "$SCENE" -o "$T/keep" --set time.end=abc
check "message names the key" -- grep -q "time.end" "$T/stderr"
expect 4 "unknown override key" -- "$RHOD" run "$SCENE" -o "$T/keep" --set time.ending=1
expect 4 "negative dx" -- "$RHOD" run "$SCENE" -o "$T/keep" --set particles.dx=-1
check "output folder untouched" -- bash -c "[ \"\$(cat '$T/keep/snapshot_0000.h5')\" = precious ] && [ \$(ls '$T/keep' | wc -l) -eq 1 ]"

# output folder problems
echo file >"$T/afile"
expect 5 "output path is a file" -- "$RHOD" run "$SCENE" -o "$T/afile" "${SHORT[@]}"
expect 5 "output under a file" -- "$RHOD" run "$SCENE" -o "$T/afile/sub" "${SHORT[@]}"
# a full disk while writing: a file size limit (EFBIG on the first snapshot, SIGXFSZ
# ignored) stands for ENOSPC; the run stops with exit 7 naming the file
expect 7 "full disk while writing" -- bash -c "ulimit -f 16; trap '' XFSZ; exec \"\$0\" \"\$@\"" \
  "$RHOD" run "$SCENE" -o "$T/full" "${SHORT[@]}"
check "write error names the file" -- grep -q "cannot write" "$T/stderr"

# an unstable run: c0 far too small for the column, a huge CFL
expect 6 "unstable run stops" -- "$RHOD" run "$SCENE" -o "$T/bad" --set particles.dx=0.05 \
  --set physics.c0=0.5 --set time.cfl=1.0 --set time.end=5 --set time.output_every=0.01
check "cause names a particle" -- grep -q "particle id" "$T/stderr"
check "summary says unstable" -- grep -q '"status": "unstable"' "$T/bad/summary.json"
check "no NaN in any snapshot" -- /usr/bin/python3 - "$T/bad" <<'PY'
import glob, sys
import h5py, numpy as np
snaps = sorted(glob.glob(sys.argv[1] + "/snapshot_*.h5"))
assert snaps, "no snapshot kept"
for s in snaps:
    with h5py.File(s) as f:
        for k in f["PartType0"]:
            a = f["PartType0"][k][()]
            if a.dtype.kind == "f" and not np.all(np.isfinite(a)):
                sys.exit(f"{s}: {k} not finite")
PY

# the stiffness limit (time.stiffness_limit, docs/choices.md): the inviscid Taylor-Green
# box at cfl 0.7, where the damper alone stays inside RK4's bound (its step limit does
# not bind) but the whole right-hand side does not; without the limit it stops near
# step 47
TG=(--set particles.dx=0.05 --set physics.mu=0 --set time.cfl=0.7 --set time.end=2
  --set time.output_every=1)
expect 0 "the stiffness limit keeps a stiff mode at bay" -- \
  "$RHOD" run "$SRC/cases/taylor_green/scene.yaml" -o "$T/stiff" "${TG[@]}"
check "the log counts the steps it set" -- grep -q "set by the stiffness the RK4 stages" \
  "$T/stiff/run.log"
check "summary counts them too" -- bash -c "grep -q '\"stiffness_limited_steps\": [1-9]' \
  '$T/stiff/summary.json'"
expect 6 "without it the same run stops" -- "$RHOD" run "$SRC/cases/taylor_green/scene.yaml" \
  -o "$T/nostiff" "${TG[@]}" --set time.stiffness_limit=false
check "the damper step limit set none of its steps" -- bash -c "! grep -q 'damper.s measured' '$T/stiff/run.log'"

# the torque_budget probe reads the state without changing the run: its scene without
# the probe gives the same other columns, bit for bit
TQ=$SRC/tests/scenes/run/rotating_torque.yaml
expect 0 "run with the torque budget" -- "$RHOD" run "$TQ" -o "$T/tq"
grep -v torque_budget "$TQ" >"$T/notq.yaml"
expect 0 "the same without it" -- "$RHOD" run "$T/notq.yaml" -o "$T/notq"
check "torque budget columns" -- bash -c "head -1 '$T/tq/probes.csv' | grep -q \
  '^t,ke,Lz,tq_pressure,tq_viscous,tq_riemann,tq_damper,tq_shifting,tq_body,tq_motion\$'"
check "the probe leaves the run alone" -- cmp -s <(cut -d, -f1-3 "$T/tq/probes.csv") \
  <(cut -d, -f1-3 "$T/notq/probes.csv")

summary cli
