#!/usr/bin/env bash
# output.fields (fields of the particle store written as well): a short RHOD-SPH run with
# refinement (splits between snapshots) writes each named field as /PartType0/<Dataset>
# with its Units and lists it in the XDMF, and the scene as run keeps the key; every other
# dataset and the probes equal those of the same run without the key, except FreeSurface,
# which the fields' output detects again at the output positions. A multiphase run writes
# its colour pass's fields and the level tag. An unknown name stops the run before
# anything is written, naming the key, the name and the fields there are.
set -uo pipefail
RHOD=$1; SRC=$2
# shellcheck source=lib_cli.sh
source "$(dirname "$0")/lib_cli.sh"
PY=/usr/bin/python3
SCENE=$SRC/tests/scenes/run/output_walls.yaml
export OMP_NUM_THREADS=1

expect 0 "run with output.fields" -- "$RHOD" run "$SCENE" -o "$T/f" \
  --set 'output.fields=[nrm, gam, V]'
expect 0 "run without" -- "$RHOD" run "$SCENE" -o "$T/p"
check "the scene as run keeps output.fields" -- grep -q "fields: \[nrm, gam, V\]" "$T/f/scene.yaml"
check "without the key, none in the scene as run" -- \
  sh -c "! grep -q 'fields:' '$T/p/scene.yaml'"
check "probes as without the fields" -- cmp -s "$T/f/probes.csv" "$T/p/probes.csv"
check "datasets, units and xdmf" -- "$PY" - "$T/f" "$T/p" <<'PYEOF'
import sys, glob, os
import h5py, numpy as np
f, p = sys.argv[1], sys.argv[2]
want = {"Normals": ("1", 3), "ShepardGamma": ("1", 1), "Volumes": ("m^2", 1)}
bad = []
snaps = sorted(glob.glob(f + "/snapshot_*.h5"))
if len(snaps) != 3:
    bad.append(f"{len(snaps)} snapshots")
for s in snaps:
    with h5py.File(s, "r") as a, h5py.File(p + "/" + os.path.basename(s), "r") as b:
        A, B = a["PartType0"], b["PartType0"]
        n = A["Coordinates"].shape[0]
        for k, (u, c) in want.items():
            if k not in A:
                bad.append(f"{s}: no {k}"); continue
            d = A[k]
            shape = (n, 3) if c == 3 else (n,)
            if d.shape != shape or d.dtype != np.float64 or d.attrs["Units"].decode() != u:
                bad.append(f"{s}: {k} {d.shape} {d.dtype} {d.attrs['Units']}")
            if not np.all(np.isfinite(d[()])):
                bad.append(f"{s}: {k} not finite")
        if c == 3 and np.any(A["Normals"][:, 2] != 0):
            bad.append(f"{s}: Normals z")
        # a free-surface particle has a unit normal; Gamma near 1 inside; V = m / rho
        fs = A["FreeSurface"][()] == 1
        nn = np.hypot(A["Normals"][:, 0], A["Normals"][:, 1])
        if not fs.any() or np.max(np.abs(nn[fs] - 1)) > 1e-5:
            bad.append(f"{s}: normals of the free surface")
        V = A["Masses"][()] / A["Densities"][()]
        single = a["Header"].attrs["Precision"] == b"single"
        if np.max(np.abs(A["Volumes"][()] / V - 1)) > (1e-6 if single else 1e-12):
            bad.append(f"{s}: Volumes != m / rho")
        for k in B:
            if k != "FreeSurface" and not np.array_equal(A[k][()], B[k][()]):
                bad.append(f"{s}: {k} differs from the run without fields")
        extra = set(A) - set(B)
        if extra != set(want):
            bad.append(f"{s}: extra datasets {sorted(extra)}")
x = open(f + "/snapshots.xdmf").read()
for k, (u, c) in want.items():
    kind = "Vector" if c == 3 else "Scalar"
    if x.count(f'<Attribute Name="{k}" AttributeType="{kind}" Center="Node">') != 3:
        bad.append(f"xdmf: {k}")
    if x.count(f"/PartType0/{k}<") != 3:
        bad.append(f"xdmf: {k} dataset")
for b in bad:
    print(b)
sys.exit(1 if bad else 0)
PYEOF

MP=$SRC/cases/oscillating_droplet/scene.yaml
expect 0 "multiphase run with output.fields" -- "$RHOD" run "$MP" -o "$T/m" \
  --set time.end=2e-6 --set time.output_every=1e-6 --set particles.dx=1e-5 \
  --set 'output.fields=[mp_col, mp_nrm, level]'
check "multiphase datasets" -- "$PY" - "$T/m/snapshot_0002.h5" <<'PYEOF'
import sys
import h5py, numpy as np
with h5py.File(sys.argv[1], "r") as a:
    A = a["PartType0"]
    n = A["Coordinates"].shape[0]
    ok = (A["Colours"].shape == (n,) and A["Normals"].shape == (n, 3)
          and A["Level"].dtype == np.uint8 and A["Level"].attrs["Units"] == b"1"
          and set(np.unique(A["Colours"][()])) == {0.0, 1.0}
          and np.array_equal(A["Colours"][()], (A["Phase"][()] == 0).astype(float))
          and np.any(np.hypot(A["Normals"][:, 0], A["Normals"][:, 1]) > 0.99))
sys.exit(0 if ok else 1)
PYEOF

expect 4 "unknown field name" -- "$RHOD" run "$SCENE" -o "$T/u" --set 'output.fields=[nrm, gamma]'
check "its message" -- grep -q \
  "output.fields.1: no field 'gamma' to write with scheme rhodsph; available: V, gam, ggam, gP, D, gC, uch, lam, nrm" \
  "$T/stderr"
check "nothing written" -- test ! -e "$T/u"
expect 4 "a field of the other scheme" -- "$RHOD" check "$MP" --set 'output.fields=[nrm]'
check "its message" -- grep -q "available: level, kind, mp_V, mp_nu, mp_col, mp_gC, mp_nrm, mp_sig" \
  "$T/stderr"
expect 4 "not an identifier" -- "$RHOD" run "$SCENE" -o "$T/u" --set 'output.fields=[a-b]'
check "its message" -- grep -q "output.fields.0: 'a-b' is not a field name" "$T/stderr"
summary output_fields
