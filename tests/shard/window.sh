#!/bin/sh
# window.sh — the window record of part format 4 (docs/scale.md;
# tests/cli/shard_window.cli). Makes the 3 parts of tests/shard/small.frac,
# whose chaos call fits its window; python3 reads each part's records: the
# window record (op 4: lo then hi as little-endian doubles) follows the
# call's two sections of sums, and the three parts hold the same doubles.
# Then:
#   - the parts with the window record taken out (the end's record count
#     and CRC-32 re-computed) still merge, the merge fitting the window
#     itself, to the single run's files, byte for byte, as the parts as
#     made do;
#   - a window with lo > hi (the record's CRC-32 re-computed) is refused.
# "skipped (…)" without python3.
set -u
frac=${FRAC:-frac}
here=$(dirname "$0")
s=$here/small.frac
if ! command -v python3 >/dev/null 2>&1; then
    echo "window: skipped (python3 is not installed to read parts)"
    exit 0
fi
tmp=$(mktemp -d "${TMPDIR:-/tmp}/frac-window-XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT
for i in 0 1 2; do
    "$frac" run -q --shard $i/3 -o "$tmp/p" "$s" || exit 1
done
p=$tmp/p/small.shard
rewrite() { # OUT-DIR MODE (keep | strip | swap): every part, its window records so treated
    mkdir -p "$1"
    python3 - "$@" "$p-0-of-3.part" "$p-1-of-3.part" "$p-2-of-3.part" <<'END'
import os, struct, sys, zlib
out, mode = sys.argv[1], sys.argv[2]
seen = []
for path in sys.argv[3:]:
    b = bytes(open(path, 'rb').read())
    assert b[:8] == b'FRACPART' and struct.unpack_from('<I', b, 8)[0] == 4, 'format'
    pos = 12
    def skip_str():
        global pos
        pos += 4 + struct.unpack_from('<I', b, pos)[0]
    skip_str(); skip_str(); pos += 32 + 8 + 4 + 32; skip_str(); pos += 8 + 4
    new, recs = bytearray(b[:pos]), []
    while b[pos:pos + 4] == b'REC ':
        call, sec, op = struct.unpack_from('<3I', b, pos + 4)
        kind = b[pos + 16:pos + 32].rstrip(b'\0').decode()
        total, unit, length = struct.unpack_from('<3Q', b, pos + 56)
        end = pos + 80 + length
        assert struct.unpack_from('<I', b, end)[0] == zlib.crc32(b[pos:end]), 'record CRC'
        rec = bytearray(b[pos:end + 4])
        recs.append((call, sec, op, kind))
        if op == 4:
            assert total == length == 32 and unit == 8, 'a 2-D window: four doubles'
            lo, hi = struct.unpack_from('<2d', b, pos + 80), struct.unpack_from('<2d', b, pos + 96)
            seen.append((call, sec, kind, lo, hi))
            if mode == 'swap':
                struct.pack_into('<2d', rec, 80, *hi)
                struct.pack_into('<2d', rec, 96, *lo)
                struct.pack_into('<I', rec, 80 + length, zlib.crc32(bytes(rec[:80 + length])))
        if not (op == 4 and mode == 'strip'):
            new += rec
        pos = end + 4
    assert b[pos:pos + 4] == b'END '
    nrec = struct.unpack_from('<I', b, pos + 4)[0]
    assert nrec == len(recs), 'record count'
    tail = bytearray(b[pos:-4])
    if mode == 'strip':
        struct.pack_into('<I', tail, 4, sum(1 for r in recs if r[2] != 4))
    new += tail + struct.pack('<I', zlib.crc32(bytes(tail)))
    open(os.path.join(out, os.path.basename(path)), 'wb').write(new)
n = len(seen) // 3
assert seen == seen[:n] * 3, 'the three shards hold different windows'
if mode == 'keep':
    print('window: records %s' % ' '.join('%d.%d/%d' % (c, s, o) for c, s, o, k in recs))
    for call, sec, kind, lo, hi in seen[:n]:
        print('window: call %d section %d (%s): lo < hi on both axes: %s; the same doubles in the 3 parts' %
              (call, sec, kind, lo[0] < hi[0] and lo[1] < hi[1]))
END
}
merge() { # NAME PART-DIR: merge, compared with the single run
    rm -rf "$tmp/out"
    "$frac" merge -q -o "$tmp/out" "$s" "$2/small.shard"-*-of-3.part >/dev/null 2>"$tmp/err"
    rc=$?
    same=no
    cmp -s "$tmp/out/a.png" "$tmp/single/a.png" && cmp -s "$tmp/out/b.pfm" "$tmp/single/b.pfm" && same=yes
    echo "$1: exit $rc, $(ls "$tmp/out" 2>/dev/null | wc -l) files written, the single run's: $same $(head -n 1 "$tmp/err" | sed "s|$tmp|TMP|g")"
}
"$frac" -q -o "$tmp/single" "$s" || exit 1
rewrite "$tmp/keep" keep || exit 1
rewrite "$tmp/strip" strip || exit 1
rewrite "$tmp/swap" swap || exit 1
merge "as made" "$tmp/p"
merge "rewritten as made" "$tmp/keep"
merge "without the window record" "$tmp/strip"
merge "lo > hi" "$tmp/swap"
