"""Reading rhod output folders: snapshots (HDF5), probes.csv, scene parameters.

Used by the cases' check and study scripts. Needs Debian's python3-numpy and
python3-h5py (installed by scripts/setup.sh), and python3-matplotlib for the plots.

As a command, `python3 tools/rhodout.py OUT` prints the run's summary (summary.json)
and plots probes.csv into OUT/probes.png, one panel per probe."""
import argparse
import csv
import datetime
import glob
import json
import os
import platform
import subprocess
import sys

import h5py
import numpy as np


def law(text, t):
    """A libmatheval expression of t (a scene's velocity or motion law) in Python."""
    import math
    names = {k: getattr(math, k) for k in ("exp", "sin", "cos", "tanh", "sqrt", "log", "pi")}
    names.update(t=t, abs=abs, min=min, max=max)
    return float(eval(text.strip('"').replace("^", "**"), {"__builtins__": {}}, names))


def lowpass(t, f, fcut):
    """f(t) low-passed at fcut: Butterworth order 4 forward and backward (paper 002
    Sec. VI E's filter of the forces); f as it is when fcut is beyond Nyquist or f is short."""
    from scipy.signal import butter, filtfilt
    dt = np.median(np.diff(t))
    if fcut * 2 * dt >= 1 or len(f) < 16:
        return f
    b, a = butter(4, fcut * 2 * dt)
    return filtfilt(b, a, f)


def snapshots(out):
    """Sorted list of snapshot paths in an output folder."""
    return sorted(glob.glob(os.path.join(out, "snapshot_*.h5")))


def read_snapshot(path):
    """Dict of numpy arrays (sorted by particle id) plus 'time'; with bodies also 'bodies':
    one (m, 2) array per body (its index in the scene's bodies), its outline's points in
    order where it stands at that time (the closed polygon of /Bodies)."""
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
        if "Bodies" in f:
            b = f["Bodies"]
            pts, seg = b["Points"][()][:, :2], b["Segments"][()]
            index = b["BodyIndex"][()]
            # each body's segments run k -> k+1 and close back: their first points in order
            d["bodies"] = [pts[seg[index == k, 0]]
                           for k in range(int(b.attrs["NumBodies"]))]
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


def finished(out):
    """Whether OUT holds a run that ended well (summary.json's status "ok")."""
    try:
        return summary(out).get("status") == "ok"
    except (OSError, ValueError):
        return False


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


# Column suffixes of the probes with several columns (rhod_probe_suffix in src/scene.c):
# a momentum probe's NAME_x, NAME_y, a torque budget's seven terms.
GROUP_SUFFIXES = ("_x", "_y", "_pressure", "_viscous", "_riemann", "_damper", "_shifting",
                  "_body", "_motion")


def probe_groups(columns):
    """The probe columns (t left out) grouped into panels: a probe's columns together."""
    groups, order = {}, []
    for c in columns:
        if c == "t":
            continue
        key = c
        for suf in GROUP_SUFFIXES:
            stem = c[: -len(suf)]
            if c.endswith(suf) and stem and sum(o.startswith(stem + "_") and
                                                 o[len(stem):] in GROUP_SUFFIXES
                                                 for o in columns) >= 2:
                key = stem
                break
        if key not in groups:
            groups[key] = []
            order.append(key)
        groups[key].append(c)
    return [(k, groups[k]) for k in order]


def plot_probes(out, path=None):
    """probes.csv of a run as a PNG (matplotlib, Agg): one panel per probe against t.
    Returns the path written, or None when the run has no probe column or no row."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    with open(os.path.join(out, "probes.csv")) as f:
        rows = [r for r in csv.reader(f) if r]
    if len(rows) < 2 or len(rows[0]) < 2:
        return None
    head = rows[0]
    data = np.array([[float(v) for v in r] for r in rows[1:]], dtype=float)
    col = {h: data[:, k] for k, h in enumerate(head)}
    groups = probe_groups(head)
    fig, axes = plt.subplots(len(groups), 1, figsize=(7, 2.2 * len(groups) + 0.6),
                             sharex=True, squeeze=False)
    for ax, (name, cols) in zip(axes[:, 0], groups):
        for c in cols:
            ax.plot(col["t"], col[c], label=c, lw=1.2, marker="." if len(data) < 30 else None)
        ax.set_ylabel(name)
        ax.grid(alpha=0.3)
        if len(cols) > 1:
            ax.legend(fontsize=7, loc="best")
    axes[-1, 0].set_xlabel("t [s]")
    fig.suptitle(os.path.basename(os.path.normpath(out)) + ": probes.csv")
    fig.tight_layout()
    path = path or os.path.join(out, "probes.png")
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def main(argv=None):
    ap = argparse.ArgumentParser(
        prog="rhodout.py",
        description="Prints a rhod run's summary and plots its probes into OUT/probes.png.")
    ap.add_argument("out", metavar="OUT", help="the run's output folder")
    args = ap.parse_args(argv)
    out = args.out
    if not os.path.isdir(out):
        print(f"rhodout.py: {out}: not a folder", file=sys.stderr)
        return 2
    try:
        s = summary(out)
    except (OSError, ValueError) as e:
        print(f"rhodout.py: {out}/summary.json: {e}", file=sys.stderr)
        return 1
    status = s.get("status", "?")
    cause = s.get("cause", "")
    print(f"{out}: {status}" + (f" ({cause})" if cause else ""))
    print(f"  time {s.get('time', 0):.6g} s, {s.get('steps', 0)} steps, "
          f"{s.get('particles', 0)} particles")
    print(f"  wall time {s.get('wall_seconds', 0):.4g} s, "
          f"{s.get('us_per_particle_step', 0):.4g} us per particle-step, "
          f"{s.get('precision', '?')} precision, kernels on {s.get('kernels_ran_on', '?')}")
    for k, v in (s.get("probes") or {}).items():
        print(f"  {k} = {v:.9g}")
    if not os.path.exists(os.path.join(out, "probes.csv")):
        print("  no probes.csv")
        return 0
    try:
        path = plot_probes(out)
    except (OSError, ValueError) as e:
        print(f"rhodout.py: {out}/probes.csv: {e}", file=sys.stderr)
        return 1
    print(f"  probes plotted: {path}" if path else "  no probe samples to plot")
    return 0


if __name__ == "__main__":
    sys.exit(main())
