#!/usr/bin/env python3
"""Draw the fit targets (examples/fit_leaf.frac, tests/cli/fit_*.cli) without frac:
a hand-made maple-leaf polygon, a Sierpinski triangle by recursive subdivision,
and the degenerate pictures of the error tests. Plain Python (zlib + struct).

    python3 examples/data/fit_targets.py      (from the repository root)
"""
import struct
import zlib


def png(path, w, h, rows):
    """rows: h lists of w grey values 0..255 (8-bit greyscale PNG)."""
    raw = b"".join(b"\x00" + bytes(r) for r in rows)

    def chunk(tag, data):
        c = struct.pack(">I", len(data)) + tag + data
        return c + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 0, 0, 0, 0)))
        f.write(chunk(b"IDAT", zlib.compress(raw, 9)))
        f.write(chunk(b"IEND", b""))


def inside(poly, x, y):
    """Even-odd rule."""
    c = False
    n = len(poly)
    for i in range(n):
        (x1, y1), (x2, y2) = poly[i], poly[(i + 1) % n]
        if (y1 > y) != (y2 > y) and x < x1 + (y - y1) * (x2 - x1) / (y2 - y1):
            c = not c
    return c


# A maple leaf drawn by hand on a 20x20 grid (x right, y down), then a stem.
LEAF = [(10, 1), (11.5, 5), (14, 4), (13, 8), (18, 6), (17, 9), (19, 10), (15, 13), (16, 15),
        (11, 14), (10.5, 19), (9.5, 19), (9, 14), (4, 15), (5, 13), (1, 10), (3, 9), (2, 6),
        (7, 8), (6, 4), (8.5, 5)]


def leaf(s):
    rows = []
    for py in range(s):
        row = []
        for px in range(s):
            x, y = (px + 0.5) * 20 / s, (py + 0.5) * 20 / s
            row.append(0 if inside(LEAF, x, y) else 255)  # dark leaf on white
        rows.append(row)
    return rows


def sierpinski(s, depth):
    """Black triangles on white: the level-`depth` subdivision of a triangle."""
    rows = [[255] * s for _ in range(s)]
    tris = [((1, s - 2), (s - 2, s - 2), ((s - 1) / 2, 1))]
    for _ in range(depth):
        nt = []
        for a, b, c in tris:
            ab = ((a[0] + b[0]) / 2, (a[1] + b[1]) / 2)
            bc = ((b[0] + c[0]) / 2, (b[1] + c[1]) / 2)
            ca = ((c[0] + a[0]) / 2, (c[1] + a[1]) / 2)
            nt += [(a, ab, ca), (ab, b, bc), (ca, bc, c)]
        tris = nt
    for tri in tris:
        for py in range(s):
            for px in range(s):
                if inside(list(tri), px + 0.5, py + 0.5):
                    rows[py][px] = 0
    return rows


if __name__ == "__main__":
    png("examples/data/leaf.png", 64, 64, leaf(64))
    png("tests/cli/data/fit_sierpinski.png", 48, 48, sierpinski(48, 4))
    png("tests/cli/data/fit_blank.png", 8, 8, [[255] * 8 for _ in range(8)])
    png("tests/cli/data/fit_dot.png", 1, 1, [[0]])
