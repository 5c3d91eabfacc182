#!/bin/sh
# format.sh — the part file as docs/scale.md describes it, read by an
# independent program (python3: hashlib's SHA-256, zlib's CRC-32, LEB128
# decoded by hand) for the 3 parts of tests/shard/small.frac
# (tests/cli/shard_format.cli). Prints what it found, or "skipped (…)".
set -u
frac=${FRAC:-frac}
here=$(dirname "$0")
s=$here/small.frac
if ! command -v python3 >/dev/null 2>&1; then
    echo "format: skipped (python3 is not installed to read the parts)"
    exit 0
fi
tmp=$(mktemp -d "${TMPDIR:-/tmp}/frac-format-XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT
for i in 0 1 2; do
    "$frac" run -q --shard $i/3 -D n=3e6 -o "$tmp/p" "$s" || exit 1
done
python3 - "$s" "$tmp"/p/small.shard-0-of-3.part "$tmp"/p/small.shard-1-of-3.part "$tmp"/p/small.shard-2-of-3.part <<'END'
import hashlib, struct, sys, zlib
script = open(sys.argv[1], 'rb').read()
sums = {}  # (call, section) -> summed values over the parts
for path in sys.argv[2:]:
    b = open(path, 'rb').read()
    pos = 0
    def take(n):
        global pos
        v = b[pos:pos + n]
        pos += n
        return v
    def u32(): return struct.unpack('<I', take(4))[0]
    def u64(): return struct.unpack('<Q', take(8))[0]
    def sstr(): return take(u32())
    assert take(8) == b'FRACPART'
    assert u32() == 3, 'format'
    sstr()  # frac version
    assert sstr() == b'sha256'
    assert take(32) == hashlib.sha256(script).digest(), 'script hash'
    assert u64() == 1, 'seed'
    assert u32() == 0 and take(32) == bytes(32), 'no frames'
    assert sstr() == b'n=3e6\n', 'params'
    index, count = u32(), u32()
    assert count == 3
    assert u32() == zlib.crc32(b[:pos - 4]) & 0xffffffff, 'header CRC'
    nrec = 0
    while True:
        start = pos
        mark = take(4)
        if mark == b'END ':
            assert u32() == nrec, 'record count'
            calls = u32()
            files = [(sstr(), take(32)) for f in range(u32())]
            assert files == [], 'files read'
            assert u32() == zlib.crc32(b[start:pos - 4]), 'end CRC'
            assert pos == len(b), 'bytes after the end'
            break
        assert mark == b'REC '
        call, sec, op = u32(), u32(), u32()
        take(16)
        chunks, lo, hi, total, unit, length = u64(), u64(), u64(), u64(), u64(), u64()
        assert (lo, hi) == (chunks * index // count, chunks * (index + 1) // count), 'chunk range'
        payload = take(length)
        assert u32() == zlib.crc32(b[start:pos - 4]), 'record CRC'
        nrec += 1
        if op != 1:
            continue
        vals, v, shift = [], 0, 0
        for c in payload:
            v |= (c & 0x7f) << shift
            shift += 7
            if not c & 0x80:
                vals.append(v)
                v, shift = 0, 0
        assert shift == 0 and len(vals) == total // 8, 'LEB128 sums'
        acc = sums.setdefault((call, sec), [0] * len(vals))
        for k, x in enumerate(vals):
            acc[k] += x
# call 0: chaos into 32x32, call 1: the 8x8 measure; each a section of
# counts, then one of plotted and inside
counts, stats = sums[(0, 0)], sums[(0, 1)]
m, ms = sums[(1, 0)], sums[(1, 1)]
print('format: 3 parts, %d records each, %d engine calls' % (nrec, calls))
print('chaos: %d bins, plotted %d, counts sum to inside: %s' % (len(counts), stats[0], sum(counts) == stats[1]))
print('measure: %d bins, plotted %d, counts sum to inside: %s' % (len(m), ms[0], sum(m) == ms[1]))
END
