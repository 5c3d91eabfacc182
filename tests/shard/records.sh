#!/bin/sh
# records.sh I/N SCRIPT [FRAC OPTIONS…] — which engine calls of SCRIPT a shard
# splits: runs `frac run --shard I/N` and lists its part's records as read by
# an independent reader (python3), one line each:
#   call C.S KIND op OP chunks C lo L hi H bytes T
# then "calls N" (the evaluation's engine calls). "skipped (…)" without python3.
set -u
frac=${FRAC:-frac}
spec=$1
script=$2
shift 2
if ! command -v python3 >/dev/null 2>&1; then
    echo "records: skipped (python3 is not installed to read the part)"
    exit 0
fi
tmp=$(mktemp -d "${TMPDIR:-/tmp}/frac-records-XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT
"$frac" run -q --threads 2 --shard "$spec" "$@" -o "$tmp" "$script" || exit 1
python3 - "$tmp"/*.part <<'END'
import struct, sys
b = open(sys.argv[1], 'rb').read()
pos = 0
def take(n):
    global pos
    v = b[pos:pos + n]
    pos += n
    return v
def u32(): return struct.unpack('<I', take(4))[0]
def u64(): return struct.unpack('<Q', take(8))[0]
def sstr(): return take(u32())
assert take(8) == b'FRACPART' and u32() == 3
sstr(); sstr(); take(32); u64(); u32(); take(32); sstr(); u32(); u32(); u32()
while True:
    mark = take(4)
    if mark == b'END ':
        u32()
        print('calls', u32())
        break
    assert mark == b'REC '
    call, sec, op = u32(), u32(), u32()
    kind = take(16).rstrip(b'\0').decode()
    chunks, lo, hi, total, unit, length = u64(), u64(), u64(), u64(), u64(), u64()
    take(length + 4)
    print('call %d.%d %s op %d chunks %d lo %d hi %d bytes %d' % (call, sec, kind, op, chunks, lo, hi, total))
END
