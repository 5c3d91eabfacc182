#!/usr/bin/python3
"""iso_vtk.py — VTK's vtkFlyingEdges3D on the volume bench/iso_bench.c sampled,
timed in the same run as frac's extractor (iso_bench calls this script).

    /usr/bin/python3 bench/iso_vtk.py VOLUME.f32 N LEVEL RUNS

VOLUME.f32: N^3 little-endian float32 samples, x fastest (iso_bench writes
the samples its own extractor meshed, so both see the same numbers).
The grid is a vtkImageData with unit spacing (the mesh's scale does not
change the work). One thread: vtkSMPTools' Sequential backend where it can
be chosen (VTK >= 9.1), else Initialize(1). vtkFlyingEdges3D with normals on
(as frac's extractor in the bench), scalars and gradients off.
Prints one line:  fe N CPU_SECONDS WALL_SECONDS TRIANGLES POINTS BACKEND FIRST_CPU
(best of RUNS for each time; CPU time of this process, which runs one thread;
FIRST_CPU is the first Update's, on fresh memory: every later Update reuses
the blocks the previous output freed).
Exit 77 with "skipped: ..." when the vtk or numpy module is missing.
"""
import sys
import time

try:
    import numpy as np
    import vtk
    from vtk.util import numpy_support
except ImportError as exc:
    print("skipped: %s (Debian: apt-get install --no-install-recommends python3-vtk9)" % exc)
    sys.exit(77)


def main():
    path, n, level, runs = sys.argv[1], int(sys.argv[2]), float(sys.argv[3]), int(sys.argv[4])
    data = np.fromfile(path, dtype="<f4")
    if data.size != n * n * n:
        print("error: %s has %d samples, not %d^3" % (path, data.size, n))
        return 1
    smp = vtk.vtkSMPTools
    backend = "Initialize(1)"
    if hasattr(smp, "SetBackend") and smp.SetBackend("Sequential"):
        backend = "Sequential"
    smp.Initialize(1)
    img = vtk.vtkImageData()
    img.SetDimensions(n, n, n)
    img.SetSpacing(1.0, 1.0, 1.0)
    img.SetOrigin(0.0, 0.0, 0.0)
    arr = numpy_support.numpy_to_vtk(data, deep=1, array_type=vtk.VTK_FLOAT)
    arr.SetName("f")
    img.GetPointData().SetScalars(arr)
    fe = vtk.vtkFlyingEdges3D()
    fe.SetInputData(img)
    fe.SetValue(0, level)
    fe.ComputeNormalsOn()
    fe.ComputeScalarsOff()
    fe.ComputeGradientsOff()
    best_cpu = best_wall = float("inf")
    tris = pts = 0
    first = None
    for _ in range(runs):
        fe.Modified()
        c0, w0 = time.process_time(), time.perf_counter()
        fe.Update()
        c1, w1 = time.process_time(), time.perf_counter()
        best_cpu, best_wall = min(best_cpu, c1 - c0), min(best_wall, w1 - w0)
        first = c1 - c0 if first is None else first
        out = fe.GetOutput()
        tris, pts = out.GetNumberOfPolys(), out.GetNumberOfPoints()
    print("fe %d %.6f %.6f %d %d %s %.6f" % (n, best_cpu, best_wall, tris, pts, backend, first))
    return 0


if __name__ == "__main__":
    sys.exit(main())
