#!/bin/sh
# sums.sh — merge checks the LEB128 sums of every record before evaluating
# (tests/cli/shard_sums.cli). Makes the 3 parts of tests/shard/small.frac
# with -D n=3e6 (bins of thousands: two-byte values among one-byte ones),
# then python3 (part.py finds the record) rewrites values of shard 1's
# first record (the 32×32 counts) and re-computes its CRC-32, so only the
# sums are wrong:
#   - a value of ten bytes whose last is 2 (more than 64 bits), placed at
#     byte 0 and at byte 5 of the payload (eight-byte steps see both);
#   - two one-byte values made one (a continuation bit set): one value short;
#   - the ten bytes of 2^64 - 1 (64 bits: valid) over ten values: nine short;
#   - the same ten bytes instead of the one-byte value at byte 5 (the
#     record's length grows by 9): valid, merged (the bin's sum wraps).
# Prints, per case, merge's exit code and first error line, and whether
# the output folder stayed empty. "skipped (…)" without python3.
set -u
frac=${FRAC:-frac}
here=$(dirname "$0")
s=$here/small.frac
if ! command -v python3 >/dev/null 2>&1; then
    echo "sums: skipped (python3 is not installed to rewrite parts)"
    exit 0
fi
tmp=$(mktemp -d "${TMPDIR:-/tmp}/frac-sums-XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT
for i in 0 1 2; do
    "$frac" run -q --shard $i/3 -D n=3e6 -o "$tmp/p" "$s" || exit 1
done
p=$tmp/p/small.shard
patch() { # OUT AT OLD HEX: payload bytes AT .. AT+OLD-1 replaced by HEX
    PYTHONPATH=$here PYTHONDONTWRITEBYTECODE=1 python3 - "$p-1-of-3.part" "$@" <<'END'
import struct, sys, zlib
import part
src, out, at, old, new = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4]), bytes.fromhex(sys.argv[5])
r = part.read(src).records[0]
b = bytearray(open(src, 'rb').read())
start, payload, length = r.start, r.at, r.length
lenat = payload - 8  # the record's length, just before its payload
assert at + old <= length
b[payload + at:payload + at + old] = new
length += len(new) - old
struct.pack_into('<Q', b, lenat, length)
end = payload + length
b[end:end + 4] = struct.pack('<I', zlib.crc32(bytes(b[start:end])))
open(out, 'wb').write(b)
END
}
case_() { # NAME PART
    rm -rf "$tmp/out"
    "$frac" merge -q -D n=3e6 -o "$tmp/out" "$s" "$p-0-of-3.part" "$2" "$p-2-of-3.part" >/dev/null 2>"$tmp/err"
    rc=$?
    files=$(ls "$tmp/out" 2>/dev/null | wc -l)
    echo "$1: exit $rc, $files files written: $(head -n 1 "$tmp/err" | sed "s|$tmp|TMP|g")"
}
case_ "as made" "$p-1-of-3.part"
patch "$tmp/a.part" 0 10 ffffffffffffffffff02
case_ "65 bits at 0" "$tmp/a.part"
patch "$tmp/b.part" 5 10 80808080808080808002
case_ "65 bits at 5" "$tmp/b.part"
patch "$tmp/c.part" 0 1 80
case_ "one short" "$tmp/c.part"
patch "$tmp/d.part" 3 10 ffffffffffffffffff01
case_ "64 bits, nine short" "$tmp/d.part"
patch "$tmp/e.part" 5 1 ffffffffffffffffff01
case_ "64 bits" "$tmp/e.part"
