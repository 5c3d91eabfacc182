#!/usr/bin/env python3
"""Compress the filtered PNG rows written by build/bench/png_bench with zlib
level 6 (CPython's zlib module) and compare with our PNG's size.

    python3 bench/png_zlib_ref.py FILTERED_FILE OUR_PNG_SIZE

Our PNG adds 57 bytes of chunk overhead (signature, IHDR, one IDAT header and
CRC per MiB, IEND) around the zlib stream; the ratio printed compares our
whole PNG to zlib's stream plus the same overhead."""
import sys
import zlib

def main():
    data = open(sys.argv[1], 'rb').read()
    ours = int(sys.argv[2])
    z6 = len(zlib.compress(data, 6))
    z9 = len(zlib.compress(data, 9))
    nidat = max(1, -(-z6 // (1 << 20)))
    overhead = 8 + 25 + 12 * nidat + 12
    print("filtered rows: %d bytes" % len(data))
    print("zlib level 6: %d bytes (+%d PNG overhead = %d)" % (z6, overhead, z6 + overhead))
    print("zlib level 9: %d bytes" % z9)
    print("our PNG: %d bytes, ratio to zlib level 6: %.4f" % (ours, ours / (z6 + overhead)))

if __name__ == '__main__':
    main()
