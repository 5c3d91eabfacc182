#!/bin/sh
# records.sh I/N SCRIPT [FRAC OPTIONS…] — which engine calls of SCRIPT a shard
# splits: runs `frac run --shard I/N` and lists its part's records as read by
# an independent reader (python3 with part.py), one line each:
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
PYTHONPATH=$(dirname "$0") PYTHONDONTWRITEBYTECODE=1 python3 - "$tmp"/*.part <<'END'
import sys
import part
p = part.read(sys.argv[1])
assert p.format == part.FORMAT, 'format'
for r in p.records:
    print('call %d.%d %s op %d chunks %d lo %d hi %d bytes %d' % (r.call, r.section, r.kind, r.op, r.chunks, r.lo, r.hi, r.total))
print('calls', p.calls)
END
