#!/bin/sh
# sums.sh — merge checks the sums of every record (LEB128 numbers, a 0
# followed by the count of its run's further zeros: docs/scale.md) before
# evaluating (tests/cli/shard_sums.cli). Makes the 3 parts of
# tests/shard/small.frac with -D n=3e6 (bins of thousands: two-byte values,
# runs of empty bins between them), then python3 (part.py finds the record,
# decodes and re-encodes its sums) rewrites shard 1's first record (the
# 32×32 counts) and re-computes its CRC-32, so only the sums are wrong:
#   - a value of ten bytes whose last is 2 (more than 64 bits), at byte 0
#     and at byte 5 of the payload (eight-byte steps see both);
#   - the first two-byte value's last byte with a continuation bit, so the
#     value runs on into the next: values are lost;
#   - the last value left out (one short), or one more (one too many);
#   - a run one zero longer (one too many), or a 0 at the very end without
#     its run's count;
#   - the first non-zero value as 2^64 - 1 (ten bytes, 64 bits: valid,
#     merged: the bin's sum wraps);
#   - every run cut into runs of at most 3 zeros: the same values (valid,
#     merged, the files the same as from the parts as made).
# Prints, per case, merge's exit code and first error line, whether the
# output folder stayed empty, and for the valid ones whether the files are
# the as-made merge's. "skipped (…)" without python3.
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
patch() { # OUT HOW [AT HEX]: shard 1's first record rewritten (HOW below)
    PYTHONPATH=$here PYTHONDONTWRITEBYTECODE=1 python3 - "$p-1-of-3.part" "$@" <<'END'
import struct, sys, zlib
import part
src, out, how = sys.argv[1], sys.argv[2], sys.argv[3]
r = part.read(src).records[0]
b = bytearray(open(src, 'rb').read())
start, payload, length = r.start, r.at, r.length
lenat = payload - 8  # the record's length, just before its payload
old = bytes(b[payload:payload + length])
vals = part.sums(old)
assert len(vals) == r.total // 8 and 0 in vals and any(v >= 128 for v in vals)
if how == 'bytes':  # bytes AT .. AT+len(HEX)-1 replaced by HEX
    at, hx = int(sys.argv[4]), bytes.fromhex(sys.argv[5])
    new = old[:at] + hx + old[at + len(hx):]
elif how == 'run-on':  # the first two-byte value's last byte continued
    k = next(i for i in range(len(old) - 1) if old[i] & 0x80 and not old[i + 1] & 0x80)
    new = old[:k + 1] + bytes([old[k + 1] | 0x80]) + old[k + 2:]
elif how == 'short':
    new = part.sums_bytes(vals[:-1])
elif how == 'long':
    new = part.sums_bytes(vals + [1])
elif how == 'long-run':  # the last run one zero longer
    k = max(i for i, v in enumerate(vals) if v == 0)
    new = part.sums_bytes(vals[:k] + [0] + vals[k:])
elif how == 'bare-zero':  # a 0 at the end without its count
    new = part.sums_bytes(vals[:-1] + [7]) [:-1] + b'\0'
elif how == 'max':
    k = next(i for i, v in enumerate(vals) if v)
    vals[k] = 2**64 - 1
    new = part.sums_bytes(vals)
elif how == 'split-runs':
    new = part.sums_bytes(vals, longest=3)
    assert len(new) > len(old)
else:
    raise SystemExit('unknown ' + how)
b[payload:payload + length] = new
length = len(new)
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
    same=
    if [ "$rc" = 0 ] && [ -d "$tmp/made" ]; then
        cmp -s "$tmp/out/a.png" "$tmp/made/a.png" && cmp -s "$tmp/out/b.pfm" "$tmp/made/b.pfm" && same=" (the as-made files)" ||
            same=" (not the as-made files)"
    fi
    echo "$1: exit $rc, $files files written$same: $(head -n 1 "$tmp/err" | sed "s|$tmp|TMP|g")"
}
case_ "as made" "$p-1-of-3.part"
mv "$tmp/out" "$tmp/made"
patch "$tmp/a.part" bytes 0 ffffffffffffffffff02
case_ "65 bits at 0" "$tmp/a.part"
patch "$tmp/b.part" bytes 5 80808080808080808002
case_ "65 bits at 5" "$tmp/b.part"
patch "$tmp/c.part" run-on
case_ "run on" "$tmp/c.part"
patch "$tmp/d.part" short
case_ "one short" "$tmp/d.part"
patch "$tmp/e.part" long
case_ "one too many" "$tmp/e.part"
patch "$tmp/f.part" long-run
case_ "a run too long" "$tmp/f.part"
patch "$tmp/g.part" bare-zero
case_ "a zero without its count" "$tmp/g.part"
patch "$tmp/h.part" max
case_ "64 bits" "$tmp/h.part"
patch "$tmp/i.part" split-runs
case_ "runs split" "$tmp/i.part"
