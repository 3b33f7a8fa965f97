#!/usr/bin/env bash
# The multiphase scheme beside bodies at rest (tests/scenes/run/mp_bodies_rest.yaml), and
# beside the same square as an obstacle wall (mp_wall_obstacle_rest.yaml: the binary before
# its faces shared the inside stops at step 68): each run reaches its end and its last
# snapshot has every particle outside the bodies and the square (the distance to the nearer
# is printed).
set -uo pipefail
RHOD=$1; SRC=$2
# shellcheck source=lib_cli.sh
source "$(dirname "$0")/lib_cli.sh"
# the nearest distance (in dx) of the last snapshot's particles to the square and, with
# "circle", the circle; exits non-zero when a particle is inside
NEAREST=$(cat <<'PY'
import sys
sys.path.insert(0, sys.argv[2] + "/tools")
import numpy as np
import rhodout
d = rhodout.read_snapshot(rhodout.snapshots(sys.argv[1])[-1])
x, y = d["pos"][:, 0], d["pos"][:, 1]
def square(x0, y0, x1, y1):
    """signed distance from [x0, x1] x [y0, y1] (negative inside)"""
    ox = np.maximum(np.maximum(x0 - x, x - x1), 0)
    oy = np.maximum(np.maximum(y0 - y, y - y1), 0)
    ins = (x > x0) & (x < x1) & (y > y0) & (y < y1)
    depth = np.minimum(np.minimum(x - x0, x1 - x), np.minimum(y - y0, y1 - y))
    return np.where(ins, -depth, np.hypot(ox, oy))
near = square(0.15, 0.54, 0.35, 0.74).min()
if sys.argv[3] == "circle":
    near = min(near, (np.hypot(x - 0.7, y - 0.4) - 0.1).min())
near /= 0.02
print(f"  {len(x)} particles; nearest to a solid {near:.3f} dx")
sys.exit(0 if near > 0 else f"a particle {near:.3f} dx from a solid")
PY
)
expect 0 "multiphase run beside two bodies at rest" -- \
  "$RHOD" run "$SRC/tests/scenes/run/mp_bodies_rest.yaml" -o "$T/run"
check "every particle outside the bodies" -- /usr/bin/python3 -c "$NEAREST" "$T/run" "$SRC" circle
expect 0 "multiphase run beside an obstacle wall at rest" -- \
  "$RHOD" run "$SRC/tests/scenes/run/mp_wall_obstacle_rest.yaml" -o "$T/wall"
check "every particle outside the obstacle wall" -- /usr/bin/python3 -c "$NEAREST" "$T/wall" "$SRC" square
summary mp_bodies
