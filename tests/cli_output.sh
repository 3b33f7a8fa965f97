#!/usr/bin/env bash
# The run's output read back by other tools: OUT/snapshots.xdmf through meshio's XDMF
# time-series reader (every step's points, vertex cells and point data equal to h5py's
# reading of that snapshot, every dataset of the snapshot present, with its Units),
# OUT/walls.xdmf through meshio (the walls as line segments on the scene's shapes), the
# provenance in /Header, and a scene without walls leaving no walls file. With pvpython
# on the PATH, tools/pvrender.py renders the last step through ParaView.
set -uo pipefail
RHOD=$1; SRC=$2
# shellcheck source=lib_cli.sh
source "$(dirname "$0")/lib_cli.sh"
PY=/usr/bin/python3
SCENE=$SRC/tests/scenes/run/output_walls.yaml

expect 0 "run" -- "$RHOD" run "$SCENE" -o "$T/out"
for f in snapshot_0000.h5 snapshot_0002.h5 snapshot_0002.png snapshots.xdmf walls.h5 \
         walls.xdmf; do
  check "output file $f" -- test -s "$T/out/$f"
done
"$RHOD" --version >"$T/version" 2>&1
check "meshio reads the snapshots and walls as h5py does" -- "$PY" - "$T/out" "$T/version" <<'PYEOF'
import re, sys
import h5py, meshio, numpy as np

out, version = sys.argv[1], open(sys.argv[2]).read()
bad = []
def need(ok, what):
    if not ok:
        bad.append(what)

# XDMF attribute name -> snapshot dataset; every dataset of /PartType0 has one
NAMES = {"Velocity": "Velocities", "Density": "Densities", "Pressure": "Pressures",
         "Mass": "Masses", "ParticleSize": "ParticleSizes", "ParticleID": "ParticleIDs",
         "FreeSurface": "FreeSurface"}
UNITS = {"Coordinates": "m", "Velocities": "m/s", "Densities": "kg/m^3", "Pressures": "Pa",
         "Masses": "kg/m", "ParticleSizes": "m", "ParticleIDs": "1", "FreeSurface": "1"}
m = re.match(r"rhod (\S+) \(commit (\S+),", version)
need(m is not None, f"--version: {version!r}")

with meshio.xdmf.TimeSeriesReader(f"{out}/snapshots.xdmf") as r:
    need(r.num_steps == 3, f"{r.num_steps} steps, expected 3")
    grids = list(r.collection)
    for k in range(r.num_steps):
        with h5py.File(f"{out}/snapshot_{k:04d}.h5", "r") as f:
            g = f["PartType0"]
            n = int(f["Header"].attrs["NumPart"])
            # meshio's reader takes the mesh of one grid: read each step's own
            r.mesh_grid = grids[k]
            pts, cells = r.read_points_cells()
            need(np.array_equal(pts, g["Coordinates"][()]), f"step {k}: points")
            need(len(cells) == 1 and cells[0].type == "vertex", f"step {k}: cells {cells}")
            if cells:
                need(np.array_equal(cells[0].data.reshape(-1), np.arange(n)),
                     f"step {k}: vertex cells are not 0..N-1")
            t, pd, _ = r.read_data(k)
            need(t == f["Header"].attrs["Time"], f"step {k}: time {t}")
            need(set(NAMES[a] for a in pd) | {"Coordinates"} == set(g.keys()),
                 f"step {k}: XDMF attributes {sorted(pd)} against datasets {sorted(g)}")
            for a, arr in pd.items():
                need(np.array_equal(arr, g[NAMES[a]][()]), f"step {k}: {a} differs")
            for d in g:
                u = g[d].attrs.get("Units")
                need(u is not None and u.decode() == UNITS[d], f"step {k}: {d} Units {u}")
            need("FreeSurface" in g, f"step {k}: no FreeSurface")
            h = f["Header"].attrs
            if m:
                need(h["CodeVersion"].decode() == m.group(1), f"CodeVersion {h['CodeVersion']}")
                need(h["GitCommit"].decode() == m.group(2), f"GitCommit {h['GitCommit']}")

w = meshio.read(f"{out}/walls.xdmf")
with h5py.File(f"{out}/walls.h5", "r") as f:
    P, S = f["Walls/Points"][()], f["Walls/Segments"][()]
    W, inside = f["Walls/WallIndex"][()], f["Walls/FluidInside"][()]
    need(f["Walls/Points"].attrs["Units"].decode() == "m", "walls: Points Units")
    need(int(f["Header"].attrs["NumWalls"]) == 3, "walls: NumWalls")
need(np.array_equal(w.points, P), "walls: points")
need(len(w.cells) == 1 and w.cells[0].type == "line", f"walls: cells {w.cells}")
need(np.array_equal(w.cells[0].data, S), "walls: segments")
need(np.array_equal(w.cell_data["WallIndex"][0], W), "walls: WallIndex")
need(list(inside) == [1, 0, 0], f"walls: FluidInside {inside}")
# each wall a closed ring of segments on its shape
for wi in range(3):
    seg = S[W == wi]
    need(len(seg) >= 3 and np.array_equal(seg[:, 1], np.roll(seg[:, 0], -1)),
         f"wall {wi}: not a closed ring")
    q = P[np.unique(seg)][:, :2]
    if wi == 0:
        need(sorted(map(tuple, q)) == [(0, 0), (0, 0.4), (0.6, 0), (0.6, 0.4)],
             f"wall 0: {q}")
    elif wi == 1:
        rr = np.hypot(q[:, 0] - 0.45, q[:, 1] - 0.1)
        need(np.allclose(rr, 0.05, rtol=0, atol=1e-12), "wall 1: off the circle")
        need(len(seg) >= 2 * np.pi * 0.05 / (0.25 * 0.02), "wall 1: segments longer than dx/4")
    else:
        need(sorted(map(tuple, q)) == sorted([(0.35, 0.3), (0.5, 0.3), (0.42, 0.38)]),
             f"wall 2: {q}")
for b in bad:
    print("  " + b)
sys.exit(1 if bad else 0)
PYEOF

# the same scene without walls, replacing the run before: no walls file left
expect 0 "run without walls" -- "$RHOD" run "$SCENE" -o "$T/out" --overwrite --set 'walls=[]' \
  --set domain.min=[0,0] --set domain.max=[0.6,0.4] --set time.end=0.001 \
  --set time.output_every=0.001
check "no walls.h5 without walls" -- test ! -e "$T/out/walls.h5"
check "no walls.xdmf without walls" -- test ! -e "$T/out/walls.xdmf"

# ParaView, where it is installed (Debian: paraview and python3-paraview; without a
# display it renders inside xvfb-run, which needs xvfb and Mesa's GLX)
PV=()
if command -v pvpython >/dev/null 2>&1; then
  if [ -n "${DISPLAY:-}" ]; then PV=(pvpython)
  elif command -v xvfb-run >/dev/null 2>&1; then PV=(xvfb-run -a -s "-screen 0 1600x1200x24" pvpython)
  fi
fi
if [ ${#PV[@]} -gt 0 ]; then
  expect 0 "run for ParaView" -- "$RHOD" run "$SCENE" -o "$T/pv"
  # ParaView's own default representation, as a user opening the folder sees it
  expect 0 "tools/pvrender.py" -- timeout 300 "${PV[@]}" "$SRC/tools/pvrender.py" "$T/pv" \
    "$T/pv/pv.png" --representation default
  check "ParaView read every particle" -- \
    grep -q "snapshots.xdmf: [0-9]* steps, last t = [0-9.e-]* s: \([1-9][0-9]*\) points, \1 cells" "$T/stdout"
  check "ParaView read the walls" -- grep -q "walls.xdmf: [1-9][0-9]* segments" "$T/stdout"
  check "ParaView picture written" -- test -s "$T/pv/pv.png"
else
  echo "cli_output: pvpython (or a display or xvfb-run) not found: tools/pvrender.py not run"
fi
summary cli_output
