#!/usr/bin/python3
"""vtk_check.py — frac's meshes (PLY, OBJ, STL) and a legacy .vtk volume
read with VTK's own readers (Debian python3-vtk9, VTK 9.1).

    /usr/bin/python3 tests/tools/vtk_check.py FRAC

Meshes: the ones of _meshes.py (Fig. 5's K_5, also the example's own
fig5.ply; a hard isosurface sphere; a spline torus; a wrinkly torus), read by
vtkPLYReader, vtkOBJReader and vtkSTLReader. For every PLY and OBJ file:
  - the triangle count; vtkFeatureEdges finds no boundary and no
    non-manifold edge (closed); vtkPolyDataConnectivityFilter counts the
    pieces (4^5 for Fig. 5, 1 otherwise);
  - the Euler characteristic V − E + F (2 per sphere-like piece, 0 for a
    torus), E counted from VTK's cells here;
  - the signed volume Σ a·(b×c)/6 over VTK's points and cells: positive
    (outward), equal to vtkMassProperties' volume, and near the value worked
    out in _meshes.py; vtkMassProperties' area near its known value.
For the STL files (which keep no shared vertices; vtkSTLReader merges equal
points): the same volume, and closed for the single-piece meshes. Fig. 5's
STL shows the documented limitation (docs/mesh.md): merged points join the
touching pieces, so VTK finds exactly 504 non-manifold edges (edges of four
triangles) there and none in the PLY.

Volume: save(sample(X + 10 Y + 100 Z, grid: [7, 5, 3], lo, hi), "v.vtk"),
read by vtkStructuredPointsReader: dimensions, spacing and origin (voxel
centres) and every value against the formula at the voxel centre.
Exit 0: all checks passed; 1: a check failed (each failure is printed);
77: the vtk module is not installed (prints "skipped: …").
"""
import os
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _meshes  # noqa: E402

try:
    import vtk
except ImportError:
    print("skipped: VTK's python module not installed (Debian python3-vtk9)")
    sys.exit(77)

vtk.vtkObject.GlobalWarningDisplayOff()
from _check import FRAC, check, finish  # noqa: E402


def read(path):
    ext = path.rsplit(".", 1)[1]
    r = {"ply": vtk.vtkPLYReader, "obj": vtk.vtkOBJReader, "stl": vtk.vtkSTLReader}[ext]()
    r.SetFileName(path)
    r.Update()
    return r.GetOutput()


def bad_edges(pd, boundary, nonmanifold):
    fe = vtk.vtkFeatureEdges()
    fe.SetInputData(pd)
    fe.SetBoundaryEdges(boundary)
    fe.SetNonManifoldEdges(nonmanifold)
    fe.FeatureEdgesOff()
    fe.ManifoldEdgesOff()
    fe.Update()
    return fe.GetOutput().GetNumberOfCells()


def pieces(pd):
    c = vtk.vtkPolyDataConnectivityFilter()
    c.SetInputData(pd)
    c.SetExtractionModeToAllRegions()
    c.Update()
    return c.GetNumberOfExtractedRegions()


def tri_stats(pd):
    """(signed volume, edge count, all cells triangles) from VTK's points and cells."""
    pts = pd.GetPoints()
    vol = 0.0
    edges = set()
    tris = True
    for i in range(pd.GetNumberOfCells()):
        ids = pd.GetCell(i).GetPointIds()
        if ids.GetNumberOfIds() != 3:
            tris = False
            continue
        v = [ids.GetId(k) for k in range(3)]
        a, b, c = (pts.GetPoint(k) for k in v)
        vol += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                a[2] * (b[0] * c[1] - b[1] * c[0]))
        for k in range(3):
            edges.add((min(v[k], v[(k + 1) % 3]), max(v[k], v[(k + 1) % 3])))
    return vol / 6, len(edges), tris


with tempfile.TemporaryDirectory() as tmp:
    facts, err = _meshes.make(FRAC, tmp)
    check(err is None, "frac ran: %s" % err)
    for name, f in (facts or {}).items():
        for ext in ["ply", "obj", "stl"]:
            fn = "%s.%s" % (name, ext)
            path = os.path.join(tmp, fn)
            if not os.path.exists(path):
                continue
            pd = read(path)
            nf = pd.GetNumberOfCells()
            if f["triangles"] is not None:
                check(nf == f["triangles"], "%s: %d triangles, expected %d" % (fn, nf, f["triangles"]))
            vol, ne, tris = tri_stats(pd)
            check(tris, "%s: every cell a triangle" % fn)
            mp = vtk.vtkMassProperties()
            mp.SetInputData(pd)
            mp.Update()
            check(vol > 0, "%s: signed volume %.9g, expected > 0 (outward)" % (fn, vol))
            check(abs(vol - mp.GetVolume()) <= 1e-6 * abs(vol), "%s: signed volume %.9g, vtkMassProperties %.9g" % (fn, vol, mp.GetVolume()))
            if f["volume"] is not None:
                check(_meshes.within(vol, f["volume"]), "%s: volume %.9g, expected %.9g within %g" % (fn, vol, *f["volume"]))
            if "volume_above" in f:
                check(vol > f["volume_above"], "%s: volume %.9g, expected above %.9g" % (fn, vol, f["volume_above"]))
            if f["area"] is not None:
                check(_meshes.within(mp.GetSurfaceArea(), f["area"]), "%s: area %.9g, expected %.9g within %g" % (fn, mp.GetSurfaceArea(), *f["area"]))
            if ext == "stl" and f["pieces"] > 1:
                # the limitation: merged points join touching pieces along 504 edges
                nm = bad_edges(pd, 0, 1)
                check(nm == 504, "%s: %d non-manifold edges after VTK merges points, expected 504" % (fn, nm))
                continue
            check(bad_edges(pd, 1, 1) == 0, "%s: boundary or non-manifold edges: %d" % (fn, bad_edges(pd, 1, 1)))
            check(pieces(pd) == f["pieces"], "%s: %d pieces, expected %d" % (fn, pieces(pd), f["pieces"]))
            euler = pd.GetNumberOfPoints() - ne + nf
            check(euler == f["euler"], "%s: Euler characteristic %d, expected %d" % (fn, euler, f["euler"]))

    # a legacy VTK volume: x + 10 y + 100 z over a box with unequal voxels
    lo, hi, n = (-1.0, 0.0, 2.0), (0.4, 1.0, 2.6), (7, 5, 3)
    script = os.path.join(tmp, "vol.frac")
    with open(script, "w") as fh:
        fh.write('save(sample(X + 10 * Y + 100 * Z, grid: %s, lo: %s, hi: %s), "v.vtk")\n' % (list(n), list(lo), list(hi)))
    r = subprocess.run([FRAC, "--quiet", "-o", tmp, script], capture_output=True, text=True)
    check(r.returncode == 0, "frac ran the volume script: exit %d %s" % (r.returncode, r.stderr))
    if r.returncode == 0:
        rd = vtk.vtkStructuredPointsReader()
        rd.SetFileName(os.path.join(tmp, "v.vtk"))
        rd.Update()
        img = rd.GetOutput()
        step = [(hi[d] - lo[d]) / n[d] for d in range(3)]
        check(img.GetDimensions() == n, "v.vtk: dimensions %s, expected %s" % (img.GetDimensions(), n))
        check(all(abs(img.GetSpacing()[d] - step[d]) < 1e-6 for d in range(3)), "v.vtk: spacing %s, expected %s" % (img.GetSpacing(), step))
        org = [lo[d] + step[d] / 2 for d in range(3)]
        check(all(abs(img.GetOrigin()[d] - org[d]) < 1e-6 for d in range(3)), "v.vtk: origin %s, expected %s" % (img.GetOrigin(), org))
        sc = img.GetPointData().GetScalars()
        bad = 0
        for k in range(n[2]):
            for j in range(n[1]):
                for i in range(n[0]):
                    x, y, z = (org[0] + i * step[0], org[1] + j * step[1], org[2] + k * step[2])
                    v = sc.GetTuple1(i + n[0] * (j + n[1] * k))
                    bad += abs(v - (x + 10 * y + 100 * z)) > 1e-4
        check(sc is not None and bad == 0, "v.vtk: %d of %d values differ from x + 10y + 100z" % (bad, n[0] * n[1] * n[2]))

finish()
