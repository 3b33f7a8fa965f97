#!/usr/bin/env bash
# Boundaries through whole runs: periodic images keep a uniform flow uniform while it
# crosses the box; no-slip and free-slip walls hold a fluid at rest.
set -euo pipefail
RHOD=$1; SRC=$2
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
"$RHOD" run "$SRC/tests/scenes/run/periodic_uniform.yaml" -o "$T/per" >/dev/null 2>&1
"$RHOD" run "$SRC/cases/hydrostatic/scene.yaml" -o "$T/noslip" --set walls.0.slip=no \
  --set particles.dx=0.05 --set time.end=0.5 --set time.output_every=0.5 >/dev/null 2>&1
/usr/bin/python3 - "$T" "$SRC" <<'PY'
import sys
sys.path.insert(0, sys.argv[2] + "/tools")
import numpy as np
import rhodout
T = sys.argv[1]
fail = 0
# periodic: every particle keeps u = (1, 0.5), the box has crossed particles over its edges
s = rhodout.read_snapshot(rhodout.snapshots(T + "/per")[-1])
s0 = rhodout.read_snapshot(rhodout.snapshots(T + "/per")[0])
dev = np.abs(s["vel"] - np.array([1.0, 0.5])).max()
moved = np.abs(s["pos"] - s0["pos"]).max()
inside = (s["pos"].min() >= -1e-12) and (s["pos"].max() <= 1 + 1e-12)
print(f"periodic: max |u - u0| = {dev:.2e}, max displacement {moved:.3f} (wrapped particles jump by ~0.8), wrapped into box: {inside}")
if not (dev < 1e-9 and inside and moved > 0.5):
    fail += 1
# no-slip tank at rest: kinetic energy stays below 1e-9 V rho0 g H
pr = rhodout.probes(T + "/noslip")
ke = pr["kinetic_energy"].max() / (0.5 * 1000 * 9.81 * 1.0)
print(f"no-slip hydrostatic: max Ek / (V rho0 g H) = {ke:.2e}")
if not ke < 1e-8:
    fail += 1
print(f"{2 - fail} passed, {fail} failed")
sys.exit(1 if fail else 0)
PY
