#!/usr/bin/python3
"""Reference figures of a short run, to hold RHOD-SPH's results while the engine changes
(issue 50: "RHOD-SPH unchanged"). For every snapshot: its time and particle count; per
field (x, y, u, v, rho, p, m, size) the sum, the sum of magnitudes, the minimum, the
maximum, and 16 particles spread over the ids, at full precision; and the last row of
probes.csv (written with 9 digits).

    refcompare.py OUT REF.txt            compare OUT with REF.txt (exit 1 on a difference)
    refcompare.py OUT REF.txt --update   write REF.txt from OUT

A value matches when it is within 1e-12 of its field's scale (the sum of magnitudes for a
sum, the largest magnitude for the others; for the velocities at least 0.01 c0, since a
fluid at rest has velocities of round-off size that any change of arithmetic order
changes wholly): the bar issue 50 sets for a change of arithmetic order. Probe values match to 2e-9 of their magnitude (they are printed with 9
digits), or to 1e-12 of the row's summed magnitudes for a probe of round-off size (the
momentum of a symmetric flow, whose round-off depends on the thread count)."""
import csv
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools"))
import rhodout  # noqa: E402

TOL, PROBE_TOL, SAMPLES = 1e-12, 2e-9, 16


def figures(out):
    """Ordered (key, value, scale) triples of a run's output."""
    rows = []
    c0 = rhodout.number(rhodout.parameters(out), "physics.c0")
    for path in rhodout.snapshots(out):
        s = os.path.basename(path)[:-3]
        d = rhodout.read_snapshot(path)
        n = len(d["id"])
        rows.append((f"{s}.time", d["time"], max(abs(d["time"]), 1e-300)))
        rows.append((f"{s}.n", float(n), 1.0))
        fields = {"x": d["pos"][:, 0], "y": d["pos"][:, 1], "u": d["vel"][:, 0],
                  "v": d["vel"][:, 1], "rho": d["rho"], "p": d["p"], "m": d["m"],
                  "size": d["size"]}
        pick = np.unique(np.linspace(0, n - 1, SAMPLES).astype(int)) if n else []
        for name, a in fields.items():
            floor = 0.01 * c0 if name in ("u", "v") else 0.0
            mag = float(np.sum(np.abs(a)))
            big = max(float(np.max(np.abs(a))) if n else 0.0, floor)
            rows.append((f"{s}.{name}.sum", float(np.sum(a)), max(mag, n * floor)))
            rows.append((f"{s}.{name}.sumabs", mag, max(mag, n * floor)))
            rows.append((f"{s}.{name}.min", float(np.min(a)), big))
            rows.append((f"{s}.{name}.max", float(np.max(a)), big))
            for k in pick:
                rows.append((f"{s}.{name}.id{int(d['id'][k])}", float(a[k]), big))
    with open(os.path.join(out, "probes.csv")) as f:
        table = list(csv.reader(f))
    last = [float(v) for v in table[-1]]
    row = sum(abs(v) for v in last)
    for name, value in zip(table[0], last):
        rows.append((f"probes.{name}", value, -row))  # negative: a probe, its row's size
    return rows


def main():
    if len(sys.argv) not in (3, 4) or (len(sys.argv) == 4 and sys.argv[3] != "--update"):
        sys.exit(__doc__)
    out, ref = sys.argv[1], sys.argv[2]
    rows = figures(out)
    if len(sys.argv) == 4:
        with open(ref, "w") as f:
            f.write(f"# refcompare.py reference: {len(rows)} figures (key value scale)\n")
            for key, value, scale in rows:
                f.write(f"{key} {value!r} {scale!r}\n")
        print(f"wrote {ref}: {len(rows)} figures")
        return
    want = {}
    with open(ref) as f:
        for line in f:
            if line.startswith("#"):
                continue
            key, value, scale = line.split()
            want[key] = (float(value), float(scale))
    got = {key: value for key, value, _ in rows}
    bad = [k for k in want if k not in got] + [k for k in got if k not in want]
    worst = 0.0
    for key, (value, scale) in want.items():
        if key not in got:
            continue
        if scale < 0:  # a probe: 9 printed digits, or 1e-12 of its row
            tol = max(PROBE_TOL * max(abs(value), abs(got[key])), -scale * TOL, 1e-300)
        else:
            tol = TOL * max(scale, abs(value), 1e-300)
        dev = abs(got[key] - value)
        worst = max(worst, dev / tol)
        if not dev <= tol:
            bad.append(f"{key}: {got[key]!r}, reference {value!r}")
    for b in bad[:10]:
        print(f"  {os.path.basename(ref)}: {b}")
    print(f"{os.path.basename(ref)}: {len(want)} figures, {len(bad)} off, largest deviation "
          f"{worst:.3g} of its tolerance")
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
