#!/usr/bin/env python3
"""Write a valid 1x1 PNG whose iTXt frac:recipe chunk holds no text at all
(tests/cli/recipe_empty_chunk.cli): the recipe parser once did pointer
arithmetic on NULL for it (fuzz finding, tests/fuzz/README.md)."""
import struct, sys, zlib

def chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

png = b"\x89PNG\r\n\x1a\n"
png += chunk(b"IHDR", struct.pack(">IIBBBBB", 1, 1, 8, 0, 0, 0, 0))
# keyword, NUL, compression flag 0, method 0, empty language, NUL, empty translated keyword, NUL, no text
png += chunk(b"iTXt", b"frac:recipe\x00\x00\x00\x00\x00")
png += chunk(b"IDAT", zlib.compress(b"\x00\x80"))
png += chunk(b"IEND", b"")
open(sys.argv[1], "wb").write(png)
