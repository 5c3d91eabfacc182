#!/bin/sh
# A PNG whose embedded script was changed (its chunk CRC made valid again)
# no longer matches its script-sha256: rerun refuses (tests/cli/recipe_damaged.cli).
T=$1
frac -q -o "$T" tests/cli/data/recipe_scene.frac > /dev/null || exit 1
if ! command -v python3 > /dev/null; then
    echo "skipped (python3 is not installed to damage the file): would check 'the file is damaged', exit 65"
    exit 0
fi
python3 - "$T/g.png" "$T/bad.png" <<'END'
import struct, sys, zlib
b = open(sys.argv[1], 'rb').read()
out, pos = b[:8], 8
while pos < len(b):
    n, = struct.unpack('>I', b[pos:pos + 4])
    t, d = b[pos + 4:pos + 8], b[pos + 8:pos + 8 + n]
    if t == b'iTXt' and d.startswith(b'frac:recipe\0'):
        head = d[:16]
        text = zlib.decompress(d[16:]).replace(b'param size = 16', b'param size = 61')
        d = head + zlib.compress(text)
    out += struct.pack('>I', len(d)) + t + d + struct.pack('>I', zlib.crc32(t + d))
    pos += 12 + n
open(sys.argv[2], 'wb').write(out)
END
frac rerun "$T/bad.png" -o "$T/b" 2>&1
echo "exit $?"
