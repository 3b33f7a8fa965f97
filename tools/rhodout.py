"""Reading rhod output folders: snapshots (HDF5), probes.csv, scene parameters.

Used by the cases' check and study scripts. Needs Debian's python3-numpy and
python3-h5py (installed by scripts/setup.sh)."""
import csv
import datetime
import glob
import json
import os
import platform
import subprocess

import h5py
import numpy as np


def snapshots(out):
    """Sorted list of snapshot paths in an output folder."""
    return sorted(glob.glob(os.path.join(out, "snapshot_*.h5")))


def read_snapshot(path):
    """Dict of numpy arrays (sorted by particle id) plus 'time'."""
    with h5py.File(path, "r") as f:
        g = f["PartType0"]
        ids = g["ParticleIDs"][()]
        order = np.argsort(ids)
        d = {"time": float(f["Header"].attrs["Time"]), "id": ids[order]}
        for key, name in (("pos", "Coordinates"), ("vel", "Velocities")):
            d[key] = g[name][()][order, :2]
        for key, name in (("rho", "Densities"), ("p", "Pressures"), ("m", "Masses"),
                          ("size", "ParticleSizes")):
            d[key] = g[name][()][order]
    return d


def parameters(out):
    """The scene as run: dotted key -> string, from the first snapshot."""
    snaps = snapshots(out)
    if not snaps:
        raise SystemExit(f"{out}: no snapshot_*.h5")
    def text(v):
        return v.decode() if isinstance(v, bytes) else str(v)
    with h5py.File(snaps[0], "r") as f:
        g = f["Parameters"]
        if "Keys" in g and "Values" in g:  # any number of keys, in scene order
            return {text(k): text(v) for k, v in zip(g["Keys"][()], g["Values"][()])}
        # older snapshots: one attribute per key
        return {k: text(v) for k, v in g.attrs.items()}


def number(params, key):
    return float(params[key])


def vector(params, key):
    return [float(v) for v in params[key].strip("[] ").split(",")]


def probes(out):
    """Columns of probes.csv as numpy arrays."""
    with open(os.path.join(out, "probes.csv")) as f:
        rows = list(csv.reader(f))
    head = rows[0]
    data = np.array([[float(v) for v in r] for r in rows[1:] if r], dtype=float)
    return {h: data[:, k] for k, h in enumerate(head)}


def summary(out):
    with open(os.path.join(out, "summary.json")) as f:
        return json.load(f)


def refdata(path):
    """Columns of a reference CSV (comment lines start with #, then a header row)."""
    with open(path) as f:
        lines = [l for l in f if not l.startswith("#") and l.strip()]
    head = lines[0].strip().split(",")
    data = np.array([[float(v) for v in l.strip().split(",")] for l in lines[1:]])
    return {h: data[:, k] for k, h in enumerate(head)}


def machine():
    """The host as results files name it: name, cores, CPU model and its widest vector
    extension (timings differ between the AVX2 and AVX-512 machines of the same kind)."""
    model, flags = "unknown CPU", set()
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name") and model == "unknown CPU":
                    model = line.split(":", 1)[1].strip()
                elif line.startswith("flags") and not flags:
                    flags = set(line.split(":", 1)[1].split())
    except OSError:
        pass
    simd = "AVX-512" if "avx512f" in flags else "AVX2" if "avx2" in flags else "SSE2"
    return f"{platform.node()} ({os.cpu_count()} cores, {model}, {simd})"


def stamp(command):
    """'Date D, commit C, machine M, command `command`' for a results file's header."""
    root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
    commit = subprocess.run(["git", "-C", root, "rev-parse", "--short", "HEAD"],
                            capture_output=True, text=True).stdout.strip()
    return f"Date {datetime.date.today()}, commit {commit}, machine {machine()}, command `{command}`"


def wendland(q, R):
    """W and dW/dr of the 2D Wendland C2 kernel (rhod's default) with support radius R."""
    c = 7 / (np.pi * R * R)
    inside = q < 1
    w = np.where(inside, c * (1 - q) ** 4 * (1 + 4 * q), 0.0)
    dw = np.where(inside, c * (-20 * q * (1 - q) ** 3) / R, 0.0)
    return w, dw


def mirror_walls(pos, walls, reach):
    """The particles plus their mirror images in straight walls, as the run's free-slip
    ghosts: walls is a list of (axis, coordinate); images of the particles within reach.
    Returns (positions, index of each point's source particle, 2 x 2 map of each point's
    velocity from its source's: identity, or the axis's component flipped)."""
    n = len(pos)
    allpos, src, maps = [pos], [np.arange(n)], [np.tile(np.eye(2), (n, 1, 1))]
    for axis, c in walls:
        near = np.where(np.abs(pos[:, axis] - c) < reach)[0]
        mp = pos[near].copy()
        mp[:, axis] = 2 * c - mp[:, axis]
        m = np.eye(2)
        m[axis, axis] = -1
        allpos.append(mp), src.append(near), maps.append(np.tile(m, (len(near), 1, 1)))
    return np.concatenate(allpos), np.concatenate(src), np.concatenate(maps)
