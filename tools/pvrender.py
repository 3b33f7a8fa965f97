#!/usr/bin/env pvpython
"""Renders the last step of a rhod run with ParaView, as a check that ParaView reads it.

    pvpython tools/pvrender.py OUT [PICTURE.png] [--field Pressure] [--representation default]

Opens OUT/snapshots.xdmf (the particles, one vertex cell each, through ParaView's XDMF
reader) and OUT/walls.xdmf (the walls as line segments, when the scene has walls), goes
to the last time step, colours the particles by the field (a node attribute of the XDMF:
Pressure [Pa], Velocity [m/s], Density [kg/m^3], Mass [kg/m], ParticleSize [m],
ParticleID, FreeSurface) with the Point Gaussian representation, draws the walls in
black, and saves a PNG (default OUT/paraview.png). Prints the number of points and
cells read, and exits non-zero when ParaView read no particles or no cells.
tests/cli_output.sh runs it when pvpython is on the PATH.
"""
import argparse
import os
import sys

from paraview import simple as pv


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[1])
    ap.add_argument("out", help="rhod output folder")
    ap.add_argument("png", nargs="?", help="picture to write (default OUT/paraview.png)")
    ap.add_argument("--field", default="Pressure", help="node attribute to colour by")
    ap.add_argument("--size", default="1200,800", help="picture size in pixels, W,H")
    ap.add_argument("--representation", default="Point Gaussian",
                    help="ParaView representation of the particles; 'default' keeps the one "
                    "ParaView picks when a user opens the file (Surface: a pixel per particle)")
    a = ap.parse_args()
    png = a.png or os.path.join(a.out, "paraview.png")
    xdmf = os.path.join(a.out, "snapshots.xdmf")
    if not os.path.exists(xdmf):
        sys.exit(f"{xdmf}: no such file")

    parts = pv.OpenDataFile(xdmf)
    times = list(getattr(parts, "TimestepValues", []) or [])
    t_last = times[-1] if times else 0.0
    parts.UpdatePipeline(t_last)
    info = parts.GetDataInformation()
    npts, ncells = info.GetNumberOfPoints(), info.GetNumberOfCells()
    print(f"{xdmf}: {len(times)} steps, last t = {t_last:g} s: {npts} points, {ncells} cells")

    view = pv.CreateView("RenderView")
    view.ViewSize = [int(v) for v in a.size.split(",")]
    view.ViewTime = t_last
    view.OrientationAxesVisibility = 0
    view.Background = [1, 1, 1]
    disp = pv.Show(parts, view)
    if a.representation != "default":
        disp.SetRepresentationType(a.representation)
    pv.ColorBy(disp, ("POINTS", a.field))
    disp.RescaleTransferFunctionToDataRange(True, False)
    disp.SetScalarBarVisibility(view, True)

    walls = os.path.join(a.out, "walls.xdmf")
    nseg = 0
    if os.path.exists(walls):
        w = pv.OpenDataFile(walls)
        w.UpdatePipeline()
        nseg = w.GetDataInformation().GetNumberOfCells()
        wd = pv.Show(w, view)
        pv.ColorBy(wd, None)
        wd.AmbientColor = wd.DiffuseColor = [0, 0, 0]
        wd.LineWidth = 2.0
        print(f"{walls}: {nseg} segments")

    view.InteractionMode = "2D"
    pv.ResetCamera(view)
    pv.SaveScreenshot(png, view)
    print(f"wrote {png}")
    if npts == 0 or ncells == 0:
        sys.exit(f"{xdmf}: ParaView read {npts} points and {ncells} cells")


if __name__ == "__main__":
    main()
