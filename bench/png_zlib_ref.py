#!/usr/bin/env python3
"""Compress the filtered PNG rows written by build/bench/png_bench with zlib
levels 2 and 6 (CPython's zlib module: zlib's own C code) and compare with
our PNG's size and encode time.

    python3 bench/png_zlib_ref.py FILTERED_FILE OUR_PNG_SIZE [OUR_SECONDS]

Our PNG adds 57 bytes of chunk overhead (signature, IHDR, one IDAT header and
CRC per MiB, IEND) around the zlib stream; the size ratio compares our whole
PNG to zlib's stream plus the same overhead. The speed ratio compares our
whole encode (filtering, deflate, Adler-32, CRCs) with zlib's compress()
alone on the already filtered rows (best of 5): stricter than libpng+zlib,
which also filters. MB/s are of raw pixels (the filtered rows less one
filter byte per row, taken from the file name's image: 1024 rows)."""
import sys
import time
import zlib

ROWS = 1024

def best_time(data, level, runs=5):
    best = None
    for _ in range(runs):
        t0 = time.perf_counter()
        z = zlib.compress(data, level)
        t = time.perf_counter() - t0
        best = t if best is None or t < best else best
    return best, len(z)

def main():
    data = open(sys.argv[1], 'rb').read()
    ours = int(sys.argv[2])
    ours_t = float(sys.argv[3]) if len(sys.argv) > 3 else None
    raw = (len(data) - ROWS) / 1e6
    print("filtered rows: %d bytes" % len(data))
    for level in (2, 6):
        t, z = best_time(data, level)
        nidat = max(1, -(-z // (1 << 20)))
        overhead = 8 + 25 + 12 * nidat + 12
        line = "  zlib level %d: %9d bytes (+%d = %d) %7.1f MB/s; ours/zlib size %.4f" % (
            level, z, overhead, z + overhead, raw / t, ours / (z + overhead))
        if ours_t:
            line += ", speed %.2fx" % (t / ours_t)
        print(line)

if __name__ == '__main__':
    main()
