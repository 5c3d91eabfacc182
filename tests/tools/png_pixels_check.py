#!/usr/bin/env python3
"""Review tool for golden updates where only the PNG compression changed:
every PNG (and APNG) under NEW whose bytes differ from the file of the same
name under OLD must decode to the same image. The decoder here is
independent of frac's: the standard library's zlib, the filter rules of the
PNG specification (§9.2-9.4) written out in Python, no Adam7 (frac does not
write interlaced files). It compares the IHDR, every ancillary chunk
(recipe text included, byte for byte) and the unfiltered rows of every frame
(IDAT, and fdAT of animated PNGs with their fcTL); only IDAT/fdAT bytes may
differ. Prints one line per changed file and exits 1 on any difference.

    png_pixels_check.py OLD_DIR NEW_DIR
    png_pixels_check.py --git REV DIR     (OLD = DIR as of git revision REV)
"""
import os
import struct
import subprocess
import sys
import zlib


def chunks(b, name):
    if b[:8] != b'\x89PNG\r\n\x1a\n':
        raise ValueError('%s: not a PNG' % name)
    pos = 8
    while pos < len(b):
        n, = struct.unpack('>I', b[pos:pos + 4])
        t = b[pos + 4:pos + 8]
        data = b[pos + 8:pos + 8 + n]
        crc, = struct.unpack('>I', b[pos + 8 + n:pos + 12 + n])
        if zlib.crc32(t + data) != crc:
            raise ValueError('%s: CRC mismatch in %r' % (name, t))
        yield t, data
        pos += 12 + n


def paeth(a, b, c):
    p = a + b - c
    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
    if pa <= pb and pa <= pc:
        return a
    return b if pb <= pc else c


def unfilter(raw, w, h, bpp_bits, name):
    """Rows of w pixels of bpp_bits bits each, filtered; returns the
    unfiltered bytes (no filter bytes)."""
    rb = (w * bpp_bits + 7) // 8
    bpp = max(1, bpp_bits // 8)
    if len(raw) != h * (rb + 1):
        raise ValueError('%s: %d bytes of image data, expected %d' % (name, len(raw), h * (rb + 1)))
    out = bytearray()
    prev = bytearray(rb)
    for y in range(h):
        ft = raw[y * (rb + 1)]
        cur = bytearray(raw[y * (rb + 1) + 1:(y + 1) * (rb + 1)])
        if ft == 1:
            for i in range(bpp, rb):
                cur[i] = (cur[i] + cur[i - bpp]) & 255
        elif ft == 2:
            for i in range(rb):
                cur[i] = (cur[i] + prev[i]) & 255
        elif ft == 3:
            for i in range(rb):
                a = cur[i - bpp] if i >= bpp else 0
                cur[i] = (cur[i] + ((a + prev[i]) >> 1)) & 255
        elif ft == 4:
            for i in range(rb):
                a = cur[i - bpp] if i >= bpp else 0
                c = prev[i - bpp] if i >= bpp else 0
                cur[i] = (cur[i] + paeth(a, prev[i], c)) & 255
        elif ft != 0:
            raise ValueError('%s: filter type %d in row %d' % (name, ft, y))
        out += cur
        prev = cur
    return bytes(out)


def decode(b, name):
    """-> (list of ancillary/other chunks, list of frames as pixel bytes)"""
    other, frames = [], []
    ihdr = None
    data = None      # zlib stream of the current frame
    size = None      # (w, h) of the current frame
    channels = {0: 1, 2: 3, 3: 1, 4: 2, 6: 4}

    def close():
        if data is not None:
            frames.append(unfilter(zlib.decompress(bytes(data)), size[0], size[1], bpp_bits, name))

    for t, d in chunks(b, name):
        if t == b'IHDR':
            ihdr = d
            w, h, depth, ct, _, _, lace = struct.unpack('>IIBBBBB', d)
            if lace:
                raise ValueError('%s: interlaced (not handled here)' % name)
            bpp_bits = depth * channels[ct]
            size = (w, h)
            other.append((t, d))
        elif t == b'fcTL':
            close()
            data = None
            size = struct.unpack('>II', d[4:12])
            other.append((t, d[4:]))  # the sequence number depends on the chunk count
        elif t == b'IDAT':
            if data is None:
                data = bytearray()
            data += d
        elif t == b'fdAT':
            if data is None:
                data = bytearray()
            data += d[4:]
        else:
            other.append((t, d))
    close()
    if ihdr is None:
        raise ValueError('%s: no IHDR' % name)
    return other, frames


def compare(old, new, name):
    o_other, o_frames = decode(old, name)
    n_other, n_frames = decode(new, name)
    if o_other != n_other:
        return 'chunks other than the image data differ'
    if len(o_frames) != len(n_frames):
        return '%d frames, was %d' % (len(n_frames), len(o_frames))
    for k, (a, b) in enumerate(zip(o_frames, n_frames)):
        if a != b:
            return 'frame %d: pixels differ' % k
    return None


def main():
    args = sys.argv[1:]
    if len(args) == 3 and args[0] == '--git':
        rev, new_dir = args[1], args[2]

        def old_bytes(rel):
            r = subprocess.run(['git', 'show', '%s:%s' % (rev, os.path.join(new_dir, rel))],
                               capture_output=True)
            return r.stdout if r.returncode == 0 else None
    elif len(args) == 2:
        old_dir, new_dir = args

        def old_bytes(rel):
            p = os.path.join(old_dir, rel)
            return open(p, 'rb').read() if os.path.exists(p) else None
    else:
        print(__doc__.strip(), file=sys.stderr)
        return 64
    bad = same = changed = 0
    for root, _, files in sorted(os.walk(new_dir)):
        for f in sorted(files):
            if not f.endswith('.png'):
                continue
            p = os.path.join(root, f)
            rel = os.path.relpath(p, new_dir)
            new = open(p, 'rb').read()
            old = old_bytes(rel)
            if old is None:
                print('%s: new file (no old version to compare)' % rel)
                bad += 1
                continue
            if old == new:
                same += 1
                continue
            changed += 1
            try:
                why = compare(old, new, rel)
            except (ValueError, zlib.error, struct.error) as ex:
                why = str(ex)
            if why:
                bad += 1
                print('%s: %s' % (rel, why))
            else:
                print('%s: same pixels (%d -> %d bytes, %.3fx)' % (rel, len(old), len(new),
                                                                   len(new) / len(old)))
    print('%d PNG files changed and decode to the same pixels, %d unchanged, %d bad'
          % (changed - bad, same, bad))
    return 1 if bad else 0


if __name__ == '__main__':
    sys.exit(main())
