"""_meshes.py — the meshes that admesh_check.py, vtk_check.py and
blender_check.py open with outside tools, and the facts each must show.

make(frac, tmp) runs FRAC once on a script that saves, as .ply, .obj and
.stl in TMP:
  fig5    seed 003 Fig. 5: {levy3d, gasket3d} on pyramid(), K_5, as in
          examples/fset_fig5.frac (whose own fig5.ply is saved too, as
          example_fig5.ply, by running the example);
  sphere  isosurface(sphere(r: 0.7), grid: 48) (a hard sphere: exact SDF);
  spline  a 48×24 torus control grid (R 1.5, r 0.6), heights 0: the plain
          spline torus;
  wrinkly the 12×6 torus of examples/wrinkly_fig11.frac with fur 0.1 (IST
          heights along the outward normal), tessellate(iterations: 1).
It returns {name: facts}; facts has the triangle count, the number of
pieces, and the known volume / area with the relative tolerance each is
held to (None: no closed form), worked out here:
  - fig5: 6·4^5 triangles in 4^5 closed pieces; volume vol(K0)·Π|det W|,
    vol(K0) = 1/36 (base rhombus √3/6 × height √3/6 / 3); each Lévy map has
    |det| = (0.5² + 0.5²)·0.707, the gasket's 1/8 each, K_5 = W1 W2 W1 W2 W1:
    (4·0.5·0.707)³ · (4/8)² / 36 (exact up to float rounding);
  - sphere: 4/3·π·0.7³ and 4·π·0.7² within 1% (the issue's bar);
  - spline: the torus 2π²Rr², 4π²Rr within 3% / 2%: a cyclic quadratic
    spline runs inside its control polygon by O(1/n²) (r·(1 - cos(2π/24))/4
    ≈ 0.5% at the middle of a v interval), which shrinks the tube;
  - wrinkly: no closed form; closed, one piece, Euler characteristic 0 (a
    torus), volume above the spline torus of the same 12×6 grid (heights >= 0
    along the outward normal only push out), given as a lower bound.
"""
import math
import os
import subprocess

SCRIPT = """import "ifs"
let K = iterate(fset([levy3d, gasket3d]), start: pyramid(), steps: 5)
let s = isosurface(sphere(r: 0.7), grid: 48)
fn torus(nu, nv) = [[[(1.5 + 0.6 * cos(tau * j / nv)) * cos(tau * i / nu), 0.6 * sin(tau * j / nv),
                      (1.5 + 0.6 * cos(tau * j / nv)) * sin(tau * i / nu)] for i in range(nu)] for j in range(nv)]
let spline = tessellate(wrinkly_surface(torus(48, 24), u: {cyclic: true}, v: {cyclic: true}), iterations: 1)
let bare = tessellate(wrinkly_surface(torus(12, 6), u: {cyclic: true}, v: {cyclic: true}), iterations: 1)
let wrinkly = tessellate(wrinkly_surface(torus(12, 6), heights: 0.1, u: {cyclic: true}, v: {cyclic: true}),
                         iterations: 1)
print(mesh_stats(bare).volume)
for ext in ["ply", "obj", "stl"] do
  save(K, "fig5." + ext)
  save(s, "sphere." + ext)
  save(spline, "spline." + ext)
  save(wrinkly, "wrinkly." + ext)
end
"""

EXAMPLE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "examples", "fset_fig5.frac")


def make(frac, tmp):
    """Run frac; return (facts, error text or None)."""
    script = os.path.join(tmp, "meshes.frac")
    with open(script, "w") as f:
        f.write(SCRIPT)
    r = subprocess.run([frac, "--quiet", "-o", tmp, script], capture_output=True, text=True)
    if r.returncode != 0:
        return None, "frac exit %d: %s" % (r.returncode, r.stderr)
    bare_volume = float(r.stdout.split()[0])
    ex = os.path.join(tmp, "example")
    os.mkdir(ex)
    r = subprocess.run([frac, "--quiet", "-o", ex, EXAMPLE], capture_output=True, text=True)
    if r.returncode != 0:
        return None, "examples/fset_fig5.frac: exit %d: %s" % (r.returncode, r.stderr)
    os.rename(os.path.join(ex, "fig5.ply"), os.path.join(tmp, "example_fig5.ply"))
    levy = 4 * 0.5 * 0.707
    fig5 = {"triangles": 6 * 4 ** 5, "pieces": 4 ** 5, "volume": (levy ** 3 * 0.5 ** 2 / 36, 1e-6),
            "area": None, "euler": 2 * 4 ** 5}
    facts = {
        "fig5": fig5,
        "example_fig5": fig5,
        "sphere": {"triangles": None, "pieces": 1, "volume": (4 / 3 * math.pi * 0.7 ** 3, 0.01),
                   "area": (4 * math.pi * 0.7 ** 2, 0.01), "euler": 2},
        "spline": {"triangles": 48 * 24 * 2 * 9, "pieces": 1, "volume": (2 * math.pi ** 2 * 1.5 * 0.36, 0.03),
                   "area": (4 * math.pi ** 2 * 1.5 * 0.6, 0.02), "euler": 0},
        "wrinkly": {"triangles": 12 * 6 * 2 * 9, "pieces": 1, "volume_above": bare_volume, "volume": None,
                    "area": None, "euler": 0},
    }
    return facts, None


def within(value, known):
    """known = (value, relative tolerance)."""
    v, tol = known
    return abs(value - v) <= tol * abs(v)
