#!/usr/bin/python3
"""apng_check.py — frac's animated PNGs checked from outside.

    /usr/bin/python3 tests/tools/apng_check.py FRAC

Renders frames with `frac run --frames`, assembles them with `frac apng`,
and saves a list of images with save(list, "x.png", {delay, loop}); then
  - decodes every file with a decoder written here (Python's zlib and struct
    only): chunk CRCs, chunk order, acTL, the fcTL fields and the one
    sequence counter over fcTL and fdAT (APNG 1.0), and each frame's pixels
    (inflated and unfiltered here) equal to the pixels of its source PNG;
  - runs `pngcheck` (Debian pngcheck) on them: exit 0 required;
  - opens them with PIL (Debian python3-pil): is_animated, n_frames, loop,
    duration and every frame's RGBA pixels;
  - splits them with `apngdis` (Debian apngdis) and compares its frames;
  - checks `frac apng`'s errors: frames of different sizes or formats, a
    corrupt or missing frame, bad --delay / --loop; nothing is written then.
A tool that is not installed prints "skipped: TOOL not installed (…)" and
its part is left out; the own decoder always runs.

Exit 0: all checks passed; 1: a check failed (each failure is printed).
"""
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import zlib

from _check import FRAC, check, finish  # noqa: E402


def chunks(data):
    """[(type, body)] of a PNG file, CRCs checked."""
    check(data[:8] == b"\x89PNG\r\n\x1a\n", "PNG signature")
    out, pos = [], 8
    while pos < len(data):
        (n,) = struct.unpack(">I", data[pos:pos + 4])
        typ, body = data[pos + 4:pos + 8], data[pos + 8:pos + 8 + n]
        (crc,) = struct.unpack(">I", data[pos + 8 + n:pos + 12 + n])
        check(zlib.crc32(typ + body) & 0xFFFFFFFF == crc, "CRC of %s at %d" % (typ, pos))
        out.append((typ.decode("latin-1"), body))
        pos += 12 + n
    return out


def unfilter(raw, w, h, bpp):
    """PNG filters 0-4 (PNG spec §9) reversed: rows of w * bpp bytes."""
    rb, rows, prev, pos = w * bpp, [], bytearray(w * bpp), 0
    for _ in range(h):
        ft, cur = raw[pos], bytearray(raw[pos + 1:pos + 1 + rb])
        pos += 1 + rb
        for i in range(rb):
            a = cur[i - bpp] if i >= bpp else 0
            b, c = prev[i], prev[i - bpp] if i >= bpp else 0
            if ft == 1:
                cur[i] = (cur[i] + a) & 255
            elif ft == 2:
                cur[i] = (cur[i] + b) & 255
            elif ft == 3:
                cur[i] = (cur[i] + (a + b) // 2) & 255
            elif ft == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                cur[i] = (cur[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
            else:
                check(ft == 0, "filter type %d" % ft)
        rows.append(bytes(cur))
        prev = cur
    check(pos == len(raw), "image data length")
    return b"".join(rows)


def ihdr_info(body):
    w, h, depth, ctype, _, _, interlace = struct.unpack(">IIBBBBB", body)
    bpp = {0: 1, 2: 3, 4: 2, 6: 4}[ctype] * depth // 8
    return w, h, depth, ctype, interlace, bpp


def png_pixels(path):
    """(w, h, pixel bytes) of a plain non-interlaced PNG, decoded here."""
    cs = chunks(open(path, "rb").read())
    w, h, _, _, interlace, bpp = ihdr_info(cs[0][1])
    check(interlace == 0, "%s not interlaced" % path)
    z = b"".join(b for t, b in cs if t == "IDAT")
    return w, h, unfilter(zlib.decompress(z), w, h, bpp)


def apng_frames(path, nframes, delay_ms, loop):
    """Check the APNG layout and return each frame's pixel bytes."""
    cs = chunks(open(path, "rb").read())
    types = [t for t, _ in cs]
    check(types[0] == "IHDR" and types[-1] == "IEND", "%s: IHDR first, IEND last" % path)
    w, h, _, _, _, bpp = ihdr_info(cs[0][1])
    check(types.index("acTL") < types.index("IDAT"), "%s: acTL before IDAT" % path)
    actl = [b for t, b in cs if t == "acTL"]
    check(len(actl) == 1 and struct.unpack(">II", actl[0]) == (nframes, loop),
          "%s: acTL %r, want %d frames, %d plays" % (path, actl and struct.unpack(">II", actl[0]), nframes, loop))
    seq, frames, cur, first_idat = 0, [], None, None
    for t, b in cs:
        if t == "fcTL":
            s, fw, fh, x, y, dn, dd, dispose, blend = struct.unpack(">IIIIIHHBB", b)
            check(s == seq, "%s: fcTL sequence %d, want %d" % (path, s, seq))
            seq += 1
            check((fw, fh, x, y) == (w, h, 0, 0), "%s: fcTL covers the canvas" % path)
            check(dn * 1000 == delay_ms * (dd or 100), "%s: delay %d/%d, want %d ms" % (path, dn, dd, delay_ms))
            check(dispose == 0 and blend == 0, "%s: dispose/blend ops" % path)
            if cur is not None:
                frames.append(cur)
            cur = b""
        elif t == "IDAT":
            check(cur is not None and not frames, "%s: IDAT belongs to the first fcTL" % path)
            cur = (cur or b"") + b
            first_idat = True
        elif t == "fdAT":
            (s,) = struct.unpack(">I", b[:4])
            check(s == seq, "%s: fdAT sequence %d, want %d" % (path, s, seq))
            seq += 1
            check(frames or cur is not None, "%s: fdAT after a fcTL" % path)
            cur += b[4:]
    frames.append(cur)
    check(first_idat, "%s: the first frame is the IDAT" % path)
    check(len(frames) == nframes, "%s: %d frames, want %d" % (path, len(frames), nframes))
    return w, h, [unfilter(zlib.decompress(z), w, h, bpp) for z in frames]


def frac(*args, cwd=None):
    return subprocess.run([FRAC] + list(args), capture_output=True, text=True, timeout=120, cwd=cwd)


def tool(name, package):
    if shutil.which(name):
        return True
    print("skipped: %s not installed (Debian %s): that part of the check is left out" % (name, package))
    return False


try:
    from PIL import Image
except ImportError:
    Image = None
    print("skipped: PIL not installed (Debian python3-pil): that part of the check is left out")

FRAMES = """
let c = [clock, 0.3 + 0.1 * frame, 1 - clock, 0.25 + 0.75 * clock]
save(gradient([20, 12], from: c, to: [0, 1, 0.5, 1], angle: 30 * frame), "f%f.png")
"""
LIST = """
let g = [gradient([9, 7], from: [k / 4, 0, 1, 0.5], to: [1, k / 4, 0, 1], angle: 40 * k) for k in range(5)]
save(g, "list.png", {delay: 250, loop: 3})
save(g, "list16.png", {bits: 16, channels: 3})
for k in range(5) do
    save(g[k], "list_%%_" + str(k) + ".png")
end
"""

with tempfile.TemporaryDirectory() as tmp:
    src = os.path.join(tmp, "frames.frac")
    open(src, "w").write(FRAMES)
    r = frac("run", "--quiet", "--frames", "0..5", "-o", tmp, src)
    check(r.returncode == 0, "--frames exit %d: %s" % (r.returncode, r.stderr))
    pngs = [os.path.join(tmp, "f%d.png" % k) for k in range(6)]
    anim = os.path.join(tmp, "anim.png")
    r = frac("apng", "-o", anim, "--delay", "120", "--loop", "2", *pngs)
    check(r.returncode == 0 and r.stderr == "wrote %s (6 frames)\n" % anim, "frac apng: %d %s" % (r.returncode, r.stderr))
    w, h, got = apng_frames(anim, 6, 120, 2)
    for k, p in enumerate(pngs):
        sw, sh, want = png_pixels(p)
        check((sw, sh) == (w, h) and k < len(got) and got[k] == want, "anim.png frame %d = %s" % (k, p))
    check(len(set(got)) == 6, "the six frames differ")

    lsrc = os.path.join(tmp, "list.frac")
    open(lsrc, "w").write(LIST)
    r = frac("run", "--quiet", "-o", tmp, lsrc)
    check(r.returncode == 0, "save(list) exit %d: %s" % (r.returncode, r.stderr))
    w, h, got = apng_frames(os.path.join(tmp, "list.png"), 5, 250, 3)
    for k in range(5):
        check(got[k] == png_pixels(os.path.join(tmp, "list_%%_%d.png" % k))[2], "list.png frame %d" % k)
    w, h, got16 = apng_frames(os.path.join(tmp, "list16.png"), 5, 40, 0)  # defaults: 40 ms, forever
    check(ihdr_info(chunks(open(os.path.join(tmp, "list16.png"), "rb").read())[0][1])[2:4] == (16, 2),
          "list16.png is 16-bit RGB")

    outs = [anim, os.path.join(tmp, "list.png"), os.path.join(tmp, "list16.png")]
    if tool("pngcheck", "pngcheck"):
        for f in outs:
            r = subprocess.run(["pngcheck", f], capture_output=True, text=True)
            check(r.returncode == 0, "pngcheck %s: %s" % (f, r.stdout + r.stderr))
    if Image:
        for f, n, dur, loop, srcs in ((anim, 6, 120, 2, pngs),
                                      (os.path.join(tmp, "list.png"), 5, 250, 3,
                                       [os.path.join(tmp, "list_%%_%d.png" % k) for k in range(5)])):
            im = Image.open(f)
            check(im.is_animated and im.n_frames == n, "PIL: %s has %d frames" % (f, n))
            check(im.info.get("loop") == loop and im.info.get("duration") == dur, "PIL: %s info %r" % (f, im.info))
            for k in range(n):
                im.seek(k)
                a = im.convert("RGBA").tobytes()
                b = Image.open(srcs[k]).convert("RGBA").tobytes()
                check(a == b, "PIL: %s frame %d equals %s" % (f, k, srcs[k]))
    if tool("apngdis", "apngdis") and Image:
        d = os.path.join(tmp, "dis")
        os.mkdir(d)
        shutil.copy(anim, os.path.join(d, "a.png"))
        r = subprocess.run(["apngdis", "a.png", "fr"], capture_output=True, text=True, cwd=d)
        check(r.returncode == 0, "apngdis: %s" % (r.stdout + r.stderr))
        for k in range(6):
            p = os.path.join(d, "fr%d.png" % (k + 1))
            check(os.path.exists(p) and Image.open(p).convert("RGBA").tobytes() ==
                  Image.open(pngs[k]).convert("RGBA").tobytes(), "apngdis frame %d" % (k + 1))

    # the example animation: a few frames of examples/anim_morph.frac, assembled
    morph = os.path.join(tmp, "morph")
    r = frac("run", "--quiet", "--frames", "0..3", "-D", "points=2e4", "-D", "size=40", "-o", morph,
             os.path.join(os.getcwd(), "examples", "anim_morph.frac"))
    check(r.returncode == 0, "anim_morph --frames 0..3: %d %s" % (r.returncode, r.stderr))
    mpngs = [os.path.join(morph, "morph_%d.png" % k) for k in range(4)]
    check(r.stdout.count("frame ") == 4 and "frame 3 s = 1 " in r.stdout, "anim_morph prints each frame: %r" % r.stdout)
    manim = os.path.join(tmp, "morph.png")
    r = frac("apng", "-q", "-o", manim, "--delay", "60", *mpngs)
    check(r.returncode == 0 and r.stderr == "", "frac apng of the morph: %d %s" % (r.returncode, r.stderr))
    w, h, got = apng_frames(manim, 4, 60, 0)
    for k, p in enumerate(mpngs):
        check(k < len(got) and got[k] == png_pixels(p)[2], "morph.png frame %d = %s" % (k, p))
    check(len(set(got)) == 4, "the morph's frames differ")
    if Image:
        check(Image.open(manim).n_frames == 4, "PIL: morph.png has 4 frames")

    # errors: nothing is written
    small = os.path.join(tmp, "small.png")
    subprocess.run([FRAC, "-q", "-e", 'save(image([3, 2]), "%s")' % small], check=True, capture_output=True)
    rgb = os.path.join(tmp, "rgb.png")
    subprocess.run([FRAC, "-q", "-e", 'save(image([20, 12]), "%s", {channels: 3})' % rgb], check=True,
                   capture_output=True)
    bad = os.path.join(tmp, "bad.png")
    data = bytearray(open(pngs[1], "rb").read())
    data[40] ^= 0xFF
    open(bad, "wb").write(bytes(data))
    out = os.path.join(tmp, "out.png")
    cases = [
        ([pngs[0], small], 65, "frac: error: %s is 8-bit RGBA 3×2, the first frame %s is 8-bit RGBA 20×12: all "
                               "frames must have the same size and format" % (small, pngs[0])),
        ([pngs[0], rgb], 65, "frac: error: %s is 8-bit RGB 20×12, the first frame %s is 8-bit RGBA 20×12: all "
                             "frames must have the same size and format" % (rgb, pngs[0])),
        ([pngs[0], bad], 65, "frac: error: %s: " % bad),
        ([pngs[0], os.path.join(tmp, "missing.png")], 74, "frac: error: "),
        (["--delay", "70000", pngs[0]], 64, "frac: --delay takes a whole number of milliseconds from 0 to 65535, "
                                            "got '70000'"),
        (["--loop", "-1", pngs[0]], 64, "frac: --loop takes a whole number of plays from 0 (forever) to "
                                        "2147483647, got '-1'"),
        (["--delay", "1.5", pngs[0]], 64, "frac: --delay takes a whole number of milliseconds from 0 to 65535, "
                                          "got '1.5'"),
    ]
    for args, code, msg in cases:
        r = frac("apng", "-o", out, *args)
        first = r.stderr.split("\n")[0]
        check(r.returncode == code and first.startswith(msg),
              "frac apng %s: exit %d (want %d), %r (want %r)" % (args, r.returncode, code, first, msg))
        check(not os.path.exists(out), "frac apng %s: nothing written" % args)
    r = frac("apng", pngs[0])
    check(r.returncode == 64 and r.stderr.startswith("frac: apng needs -o OUT.png, the file to write"),
          "apng without -o: %r" % r.stderr)
    r = frac("apng", "-o", out)
    check(r.returncode == 64 and r.stderr.startswith("frac: apng needs frames: frac apng -o OUT.png FRAME.png..."),
          "apng without frames: %r" % r.stderr)

finish()
