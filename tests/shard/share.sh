#!/bin/sh
# share.sh SCRIPT [FRAC OPTIONS…] — a shard's part holds only its share.
#
# Runs SCRIPT as 1 shard and as 3 shards, reads the parts with an independent
# program (python3 with part.py; the format of docs/scale.md) and prints, for
# every record, its engine call, section, kind, op, chunk count and the
# payload bytes of the one part of N=1 and of each of the 3 parts. For a rows record it checks
# that each part of N=3 carries exactly the rows of its chunk range and that
# the three payloads put end to end are the payload of N=1, byte for byte.
# Prints "skipped (…)" without python3. FRAC (default: frac on PATH).
set -u
frac=${FRAC:-frac}
script=$1
shift
name=$(basename "$script" .frac)
if ! command -v python3 >/dev/null 2>&1; then
    echo "share: skipped (python3 is not installed to read the parts)"
    exit 0
fi
tmp=$(mktemp -d "${TMPDIR:-/tmp}/frac-share-XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT
"$frac" run -q --threads 1 --shard 0/1 "$@" -o "$tmp/p1" "$script" || exit 1
for i in 0 1 2; do
    "$frac" run -q --threads 1 --shard $i/3 "$@" -o "$tmp/p3" "$script" || exit 1
done
PYTHONPATH=$(dirname "$0") PYTHONDONTWRITEBYTECODE=1 python3 - "$tmp/p1/$name.shard-0-of-1.part" "$tmp/p3/$name.shard-0-of-3.part" \
    "$tmp/p3/$name.shard-1-of-3.part" "$tmp/p3/$name.shard-2-of-3.part" <<'END'
import sys
import part

def records(path):
    p = part.read(path)  # checks the markers, every CRC and that none is truncated
    assert p.format == part.FORMAT, 'format'
    out = []
    for r in p.records:
        assert (r.lo, r.hi) == (r.chunks * p.index // p.count, r.chunks * (p.index + 1) // p.count), 'chunk range'
        if r.op == 2:  # rows: chunks lo .. hi-1 only
            assert r.length == min(r.hi * r.unit, r.total) - min(r.lo * r.unit, r.total), 'rows of the range'
        out.append((r.call, r.section, r.op, r.kind, r.chunks, r.unit, r.total, r.payload))
    return out

one = records(sys.argv[1])
three = [records(p) for p in sys.argv[2:]]
assert all(len(r) == len(one) for r in three), 'the same records in every part'
ops = {1: 'sums', 2: 'rows', 3: 'combine'}
for k, (call, sec, op, kind, chunks, unit, total, payload) in enumerate(one):
    parts = [r[k] for r in three]
    assert all(p[:7] == one[k][:7] for p in parts), 'record %d differs between the parts' % k
    assert len(payload) == total, 'N=1 holds it all'
    if op == 2:
        assert b''.join(p[7] for p in parts) == payload, 'the rows of N=3 end to end are those of N=1'
    print('call %d section %d %s %s: %d chunks of %d bytes; N=1 %d bytes; N=3 %s' %
          (call, sec, kind, ops[op], chunks, unit, len(payload), ' + '.join(str(len(p[7])) for p in parts)))
END
