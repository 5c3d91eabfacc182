#!/usr/bin/python3
"""mesh_check.py — frac's 3-D function-set meshes (seed 003 §3-4, Fig. 5)
read back by readers written here from the format specs (PLY, OBJ, binary
STL), independently of frac's own mesh_io.c and mesh_stats.

    /usr/bin/python3 tests/tools/mesh_check.py FRAC

Runs FRAC on a script that iterates (a) three half-scale maps of the unit
cube (translations (0,0,0), (1,0,0), (0,0,1); pieces disjoint) and (b) Fig.
5's set {levy3d, gasket3d} on pyramid(), and saves each as .ply, .obj and
.stl. For every file it checks, against values worked by hand:
  - vertex and triangle counts: |V(K0)|·4^n and |T(K0)|·m^n;
  - closed and consistently wound: every undirected edge in exactly two
    triangles, once in each direction (STL, which has no shared vertices:
    after welding equal positions, so only for (a), whose pieces are apart);
  - signed volume Σ a·(b×c)/6 = vol(K0)·(Σ|det A_i|)^n (positive: outward);
  - (a) the bounding box [0, 1.875] × [0, 0.125] × [0, 1.875] at n = 3.
Exit 0: all checks passed; 1: a check failed (each failure is printed).
"""
import os
import struct
import subprocess
import sys
import tempfile

FRAC = sys.argv[1]
fails = []


def check(cond, what):
    if not cond:
        fails.append(what)
        print("FAIL:", what)


def read_ply(path):
    data = open(path, "rb").read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii").split("\n")
    assert header[0] == "ply" and header[1] == "format binary_little_endian 1.0", header[:2]
    nv = nf = 0
    vprops = []
    cur = None
    for line in header:
        w = line.split()
        if w[:1] == ["element"]:
            cur = w[1]
            if cur == "vertex":
                nv = int(w[2])
            elif cur == "face":
                nf = int(w[2])
        elif w[:1] == ["property"] and cur == "vertex":
            vprops.append(w[1])
    sizes = {"float": 4, "uchar": 1}
    vsize = sum(sizes[t] for t in vprops)
    assert vprops[:3] == ["float"] * 3
    pos = []
    off = end
    for i in range(nv):
        pos.append(struct.unpack_from("<3f", data, off))
        off += vsize
    tris = []
    for i in range(nf):
        (k,) = struct.unpack_from("<B", data, off)
        assert k == 3, k
        tris.append(struct.unpack_from("<3i", data, off + 1))
        off += 1 + 12
    assert off == len(data), (off, len(data))
    return pos, tris


def read_obj(path):
    pos, tris = [], []
    for line in open(path):
        w = line.split()
        if w[:1] == ["v"]:
            pos.append(tuple(float(x) for x in w[1:4]))
        elif w[:1] == ["f"]:
            tris.append(tuple(int(c.split("/")[0]) - 1 for c in w[1:4]))
    return pos, tris


def read_stl(path):
    data = open(path, "rb").read()
    (n,) = struct.unpack_from("<I", data, 80)
    assert len(data) == 84 + 50 * n
    index, pos, tris = {}, [], []
    for t in range(n):
        base = 84 + 50 * t + 12
        tri = []
        for c in range(3):
            p = struct.unpack_from("<3f", data, base + 12 * c)
            if p not in index:
                index[p] = len(pos)
                pos.append(p)
            tri.append(index[p])
        tris.append(tuple(tri))
    return pos, tris


def closed_and_wound(tris):
    directed = {}
    for t in tris:
        for k in range(3):
            e = (t[k], t[(k + 1) % 3])
            directed[e] = directed.get(e, 0) + 1
    return all(c == 1 for c in directed.values()) and all((b, a) in directed for (a, b) in directed)


def volume(pos, tris):
    v = 0.0
    for a, b, c in tris:
        p, q, r = pos[a], pos[b], pos[c]
        v += (p[0] * (q[1] * r[2] - q[2] * r[1]) - p[1] * (q[0] * r[2] - q[2] * r[0]) +
              p[2] * (q[0] * r[1] - q[1] * r[0]))
    return v / 6


SCRIPT = """import "ifs"
let three = ifs {
  .5 0 0  0 .5 0  0 0 .5   0 0 0
  .5 0 0  0 .5 0  0 0 .5   1 0 0
  .5 0 0  0 .5 0  0 0 .5   0 0 1
}
let a = iterate(three, start: cube(), steps: 3)
let b = iterate(fset([levy3d, gasket3d]), start: pyramid(), steps: 5)
for ext in ["ply", "obj", "stl"] do
  save(a, "a." + ext)
  save(b, "b." + ext)
end
"""

with tempfile.TemporaryDirectory() as tmp:
    script = os.path.join(tmp, "k.frac")
    open(script, "w").write(SCRIPT)
    r = subprocess.run([FRAC, "--quiet", "-o", tmp, script], capture_output=True, text=True)
    check(r.returncode == 0, "frac ran: exit %d, %s" % (r.returncode, r.stderr))
    if r.returncode == 0:
        # the Lévy maps: |det| = (0.5·0.5 + 0.5·0.5)·0.707 each (negative: they
        # mirror, and K_5 has three Lévy steps, so every copy mirrors); the gasket's 1/8
        levy = 4 * 0.5 * 0.707
        cases = {"a": (8 * 27, 12 * 27, (3 / 8) ** 3),
                 "b": (5 * 4 ** 5, 6 * 4 ** 5, (1 / 36) * levy ** 3 * 0.5 ** 2)}
        readers = {"ply": read_ply, "obj": read_obj, "stl": read_stl}
        for name, (nv, nt, vol) in cases.items():
            for ext, reader in readers.items():
                f = "%s.%s" % (name, ext)
                pos, tris = reader(os.path.join(tmp, f))
                if ext != "stl":  # STL keeps no vertex list; welding merges equal corners
                    check(len(pos) == nv, "%s: %d vertices, expected %d" % (f, len(pos), nv))
                check(len(tris) == nt, "%s: %d triangles, expected %d" % (f, len(tris), nt))
                # (b's pieces touch, so welding an STL joins them: its edges are checked in PLY/OBJ)
                if ext != "stl" or name == "a":
                    check(closed_and_wound(tris), "%s: every edge in two triangles, once each way" % f)
                v = volume(pos, tris)
                check(abs(v - vol) < 1e-6 * max(1, vol), "%s: volume %.9g, expected %.9g" % (f, v, vol))
                if name == "a":
                    lo = [min(p[d] for p in pos) for d in range(3)]
                    hi = [max(p[d] for p in pos) for d in range(3)]
                    check(lo == [0, 0, 0] and hi == [1.875, 0.125, 1.875], "%s: box %s %s" % (f, lo, hi))

sys.exit(1 if fails else 0)
