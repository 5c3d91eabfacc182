#!/bin/sh
# format.sh — the part file as docs/scale.md describes it, read by an
# independent program (python3 with part.py: hashlib's SHA-256, zlib's
# CRC-32, LEB128 and the runs of zeros decoded by hand) for the 3 parts of
# tests/shard/small.frac (tests/cli/shard_format.cli). Prints what it found, or "skipped (…)".
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
PYTHONPATH=$here PYTHONDONTWRITEBYTECODE=1 python3 - "$s" "$tmp"/p/small.shard-0-of-3.part "$tmp"/p/small.shard-1-of-3.part "$tmp"/p/small.shard-2-of-3.part <<'END'
import hashlib, sys
import part
script = open(sys.argv[1], 'rb').read()
sums = {}  # (call, section) -> summed values over the parts
for path in sys.argv[2:]:
    p = part.read(path)  # checks the magic, markers, CRCs, record count, the end
    assert p.format == part.FORMAT, 'format'
    assert p.hash_name == b'sha256'
    assert p.script_hash == hashlib.sha256(script).digest(), 'script hash'
    assert p.seed == 1, 'seed'
    assert p.frames == 0 and p.frame == (0, 0, 0, 0), 'no frames'
    assert p.params == b'n=3e6\n', 'params'
    assert p.count == 3
    assert p.files == [], 'files read'
    nrec, calls = len(p.records), p.calls
    for r in p.records:
        assert (r.lo, r.hi) == (r.chunks * p.index // p.count, r.chunks * (p.index + 1) // p.count), 'chunk range'
        if r.op != 1:
            continue
        vals = part.sums(r.payload)
        assert len(vals) == r.total // 8, 'LEB128 sums'
        acc = sums.setdefault((r.call, r.section), [0] * len(vals))
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
