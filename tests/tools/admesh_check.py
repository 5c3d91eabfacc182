#!/usr/bin/python3
"""admesh_check.py — frac's binary STL files checked with ADMesh (Debian
admesh, 0.98.4), an STL tool independent of frac.

    /usr/bin/python3 tests/tools/admesh_check.py FRAC

Saves the meshes of _meshes.py (Fig. 5's K_5, a hard isosurface sphere, a
spline torus and a wrinkly torus) as .stl and runs `admesh FILE` on each.
ADMesh matches facet edges by exact vertex positions, repairs what it can
and prints what it found in the original file; for every file this checks:
  - the facet count, and 0 facets with 1, 2 or 3 disconnected edges (closed:
    every edge met by another facet), 0 degenerate facets;
  - "Facets reversed" 0 and "Backwards edges" 0: the winding is consistent
    and outward already (ADMesh reverses facets that disagree with their
    neighbours, and all of them when the volume comes out negative);
  - "Normals fixed" 0: the stored facet normals agree with the winding;
  - "Number of parts": 4^5 for Fig. 5 (its pieces stay apart even where
    they touch: ADMesh pairs each edge with one neighbour), 1 for the rest;
  - the volume: positive, and near the value worked out in _meshes.py.
Exit 0: all checks passed; 1: a check failed (each failure is printed);
77: admesh is not installed (prints "skipped: …").
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _meshes  # noqa: E402

if not shutil.which("admesh"):
    print("skipped: admesh not installed (Debian admesh)")
    sys.exit(77)

from _check import FRAC, check, finish  # noqa: E402


def field(text, name):
    """The first number after 'name :' (the Original column where there are two)."""
    m = re.search(re.escape(name) + r"\s*:\s*(-?[0-9.]+)", text)
    return float(m.group(1)) if m else None


with tempfile.TemporaryDirectory() as tmp:
    facts, err = _meshes.make(FRAC, tmp)
    check(err is None, "frac ran: %s" % err)
    for name, f in (facts or {}).items():
        path = os.path.join(tmp, name + ".stl")
        if not os.path.exists(path):
            continue
        r = subprocess.run(["admesh", path], capture_output=True, text=True, cwd=tmp)
        out = r.stdout
        check(r.returncode == 0 and "Results produced by ADMesh" in out, "%s.stl: admesh ran: exit %d %s" % (name, r.returncode, r.stderr))
        got = {k: field(out, k) for k in [
            "Number of facets", "Facets with 1 disconnected edge", "Facets with 2 disconnected edges",
            "Facets with 3 disconnected edges", "Total disconnected facets", "Number of parts",
            "Degenerate facets", "Facets reversed", "Backwards edges", "Normals fixed", "Volume"]}
        if f["triangles"] is not None:
            check(got["Number of facets"] == f["triangles"], "%s.stl: %s facets, expected %d" % (name, got["Number of facets"], f["triangles"]))
        for k in ["Facets with 1 disconnected edge", "Facets with 2 disconnected edges",
                  "Facets with 3 disconnected edges", "Total disconnected facets", "Degenerate facets",
                  "Facets reversed", "Backwards edges", "Normals fixed"]:
            check(got[k] == 0, "%s.stl: %s: %s, expected 0" % (name, k, got[k]))
        check(got["Number of parts"] == f["pieces"], "%s.stl: %s parts, expected %d" % (name, got["Number of parts"], f["pieces"]))
        vol = got["Volume"]
        check(vol is not None and vol > 0, "%s.stl: volume %s, expected > 0" % (name, vol))
        if vol is not None and f["volume"] is not None:
            # admesh prints 6 decimals: allow that rounding
            known, tol = f["volume"]
            check(abs(vol - known) <= max(tol * known, 1e-6), "%s.stl: volume %.6f, expected %.6f within %g" % (name, vol, known, tol))
        if vol is not None and "volume_above" in f:
            check(vol > f["volume_above"], "%s.stl: volume %.6f, expected above %.6f" % (name, vol, f["volume_above"]))

finish()
