#!/usr/bin/python3
"""vdb_check.py — frac's .vdb files checked with the OpenVDB library itself.

    /usr/bin/python3 tests/tools/vdb_check.py FRAC

Runs FRAC on a script that samples fields with known formulas into volumes
and saves them as .vdb (the language path: save(v, "x.vdb", {grids: …})),
then opens the file with pyopenvdb (Debian python3-openvdb, OpenVDB 10) and
checks grid names, classes and types, the transform (voxel size and the world
position of index (0, 0, 0)), active voxel counts and values against the
formulas. Then pyopenvdb writes a file (blosc-compressed, its default) and
frac must refuse it with its exact message.

Exit 0: all checks passed; 1: a check failed (each failure is printed);
77: python3-openvdb is not installed (prints "skipped: …").
"""
import os
import subprocess
import sys
import tempfile

try:
    import pyopenvdb as vdb
except ImportError:
    print("skipped: python3-openvdb not installed")
    sys.exit(77)

FRAC = sys.argv[1]
fails = []


def check(cond, what):
    if not cond:
        fails.append(what)
        print("FAIL:", what)


def near(a, b, tol=1e-5):
    return abs(a - b) <= tol * max(1.0, abs(b))


# density: v = x + 10 y + 100 z on a 13×9×5 grid over a box whose voxels are
# not cubes (0.2 × 0.25 × 0.1), so an axis swap or flip changes values;
# temperature: sparse, max(x - 0.2, 0) * (1 + y) is zero for x <= 0.2;
# color: (x, y, z) of the density's box.
LO, HI, N = (-1.0, -0.5, 2.0), (1.6, 1.75, 2.5), (13, 9, 5)
TLO, THI, TN = (-1.0, -1.0, -1.0), (1.0, 1.0, 1.0), (40, 24, 20)
SCRIPT = f"""
let d = sample(X + 10 * Y + 100 * Z, grid: [13, 9, 5], lo: {list(LO)}, hi: {list(HI)})
let t = sample(max(X - 0.2, 0) * (1 + Y), grid: [40, 24, 20])
let c = [sample(X, grid: [13, 9, 5], lo: {list(LO)}, hi: {list(HI)}),
         sample(Y, grid: [13, 9, 5], lo: {list(LO)}, hi: {list(HI)}),
         sample(Z, grid: [13, 9, 5], lo: {list(LO)}, hi: {list(HI)})]
save(d, "check.vdb", {{grids: {{temperature: t, color: c}}}})
"""


def centre(lo, hi, n, i):
    return lo + (hi - lo) * (i + 0.5) / n


with tempfile.TemporaryDirectory() as tmp:
    r = subprocess.run([FRAC, "--quiet", "-o", tmp, "-"], input=SCRIPT, capture_output=True, text=True)
    check(r.returncode == 0, f"frac exit {r.returncode}: {r.stderr}")
    path = os.path.join(tmp, "check.vdb")
    if r.returncode == 0:
        grids, meta = vdb.readAll(path)
        by = {g.name: g for g in grids}
        check(sorted(by) == ["color", "density", "temperature"], f"grid names {sorted(by)}")
        d, t, c = by.get("density"), by.get("temperature"), by.get("color")
        if d and t and c:
            check(type(d).__name__ == "FloatGrid" and type(t).__name__ == "FloatGrid", "float grids")
            check(type(c).__name__ == "Vec3SGrid", "color is a Vec3SGrid")
            check(d.gridClass == vdb.GridClass.FOG_VOLUME, f"density class {d.gridClass}")
            check(t.gridClass == vdb.GridClass.FOG_VOLUME, f"temperature class {t.gridClass}")
            check(d.background == 0.0 and t.background == 0.0, "background 0")
            s = [(HI[a] - LO[a]) / N[a] for a in range(3)]
            vs = d.transform.voxelSize()
            check(all(near(vs[a], s[a], 1e-12) for a in range(3)), f"density voxel size {vs} vs {s}")
            w0 = d.transform.indexToWorld((0, 0, 0))
            check(all(near(w0[a], LO[a] + s[a] / 2, 1e-12) for a in range(3)), f"index (0,0,0) at {w0}")
            w1 = d.transform.indexToWorld((12, 8, 4))
            check(all(near(w1[a], centre(LO[a], HI[a], N[a], (12, 8, 4)[a]), 1e-12) for a in range(3)),
                  f"index (12,8,4) at {w1}")
            wt = t.transform.indexToWorld((0, 0, 0))
            check(all(near(wt[a], -1 + 1.0 / TN[a], 1e-12) for a in range(3)), f"temperature (0,0,0) at {wt}")
            # density is non-zero wherever x + 10y + 100z != 0: z >= 2 makes it
            # positive everywhere, so every voxel is active
            check(d.activeVoxelCount() == 13 * 9 * 5, f"density active {d.activeVoxelCount()}")
            check(d.evalActiveVoxelBoundingBox() == ((0, 0, 0), (12, 8, 4)),
                  f"density bbox {d.evalActiveVoxelBoundingBox()}")
            acc = d.getConstAccessor()
            bad = 0
            for k in range(5):
                for j in range(9):
                    for i in range(13):
                        x, y, z = (centre(LO[a], HI[a], N[a], (i, j, k)[a]) for a in range(3))
                        if not near(acc.getValue((i, j, k)), x + 10 * y + 100 * z):
                            bad += 1
            check(bad == 0, f"{bad} density values differ from x + 10y + 100z")
            check(acc.getValue((13, 0, 0)) == 0.0 and not acc.isValueOn((13, 0, 0)), "outside: inactive 0")
            # temperature: x > 0.2 for i >= 24 (centres 0.225, 0.275, …)
            check(t.activeVoxelCount() == 16 * 24 * 20, f"temperature active {t.activeVoxelCount()}")
            ta = t.getConstAccessor()
            bad = 0
            for (i, j, k) in [(24, 0, 0), (39, 23, 19), (30, 7, 11), (23, 5, 5), (0, 0, 0)]:
                x, y = centre(-1, 1, 40, i), centre(-1, 1, 24, j)
                want = max(x - 0.2, 0) * (1 + y)
                if not near(ta.getValue((i, j, k)), want) or ta.isValueOn((i, j, k)) != (want != 0):
                    bad += 1
                    print("temperature", (i, j, k), ta.getValue((i, j, k)), want)
            check(bad == 0, "temperature values")
            ca = c.getConstAccessor()
            v = ca.getValue((3, 7, 2))
            want = tuple(centre(LO[a], HI[a], N[a], (3, 7, 2)[a]) for a in range(3))
            check(all(near(v[a], want[a]) for a in range(3)), f"color (3,7,2) = {v} vs {want}")
            check(d.metadata.get("creator") == "frac", "creator metadata")
            check(tuple(d.metadata.get("frac_size", ())) == N, "frac_size metadata")

    # the other way: OpenVDB's own (blosc-compressed) file is refused clearly
    g = vdb.FloatGrid()
    g.name = "density"
    g.getAccessor().setValueOn((1, 2, 3), 4.0)
    pv = os.path.join(tmp, "py.vdb")
    vdb.write(pv, grids=[g])
    r = subprocess.run([FRAC, "--quiet", "-e", f'load_volume("{pv}")'], capture_output=True, text=True)
    want = ("error: load_volume: grid 'density' is compressed with blosc; "
            "frac reads .vdb files saved without zip or blosc")
    check(r.returncode == 65 and want in r.stderr, f"pyopenvdb file: exit {r.returncode}, {r.stderr.strip()}")

if fails:
    print(f"vdb_check: {len(fails)} failed")
    sys.exit(1)
print(f"vdb_check: all passed (OpenVDB {'.'.join(map(str, vdb.LIBRARY_VERSION))}, "
      f"file format {vdb.FILE_FORMAT_VERSION})")
