#!/bin/sh
# unused.sh — merge checks that the parts fit this evaluation
# (tests/cli/shard_unused.cli):
#  1. the shards' script imports ./lib.frac; lib.frac changes before the
#     merge: refused before anything is evaluated (the parts carry the
#     SHA-256 of every file the shards read);
#  2. parts whose last record no engine call of the merge's evaluation uses
#     (made here by giving a script of one engine call the parts of a script
#     of two, with python3 rewriting the hash in their headers): refused
#     after the evaluation, naming the record;
#  3. a part read other files than the others: refused.
# Prints, per case, the exit code, the files written and the first error line.
set -u
frac=${FRAC:-frac}
tmp=$(mktemp -d "${TMPDIR:-/tmp}/frac-unused-XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT
cd "$tmp" || exit 1
cat >lib.frac <<'END'
let n = 2e4
END
cat >two.frac <<'END'
import "./lib.frac" as lib
let tri = ifs {
  0.5 0 0 0.5 0    0    0.34
  0.5 0 0 0.5 0.5  0    0.33
  0.5 0 0 0.5 0.25 0.5  0.33
}
let a = chaos(tri, points: lib.n, size: 16)
save(measure(tri, grid: [8, 8], points: lib.n, lo: [0, 0], hi: [1, 1]), "b.pfm")
END
for i in 0 1; do
    "$frac" run -q --shard $i/2 -o p two.frac || exit 1
done
case_() { # NAME, then the merge arguments
    name=$1
    shift
    rm -rf out
    "$frac" merge -q -o out "$@" >/dev/null 2>err
    rc=$?
    echo "$name: exit $rc, $(ls out 2>/dev/null | wc -l) files written: $(head -n 1 err | sed "s|$tmp|TMP|g")"
}
case_ "unchanged" two.frac p/two.shard-0-of-2.part p/two.shard-1-of-2.part
cp lib.frac lib.orig
echo 'let n = 3e4' >lib.frac
case_ "import changed" two.frac p/two.shard-0-of-2.part p/two.shard-1-of-2.part
cp lib.orig lib.frac
mkdir q
echo 'let n = 2e4' >q/lib.frac
cp two.frac q/two.frac
(cd q && "$frac" run -q --shard 1/2 -o ../p2 two.frac) || exit 1
case_ "other files" two.frac p/two.shard-0-of-2.part p2/two.shard-1-of-2.part
if ! command -v python3 >/dev/null 2>&1; then
    echo "unused record: skipped (python3 is not installed to rewrite the parts)"
    exit 0
fi
# one.frac: the first engine call of two.frac only (it saves nothing)
head -n 7 two.frac >one.frac
echo 'print("one call")' >>one.frac
python3 - one.frac p/two.shard-0-of-2.part p/two.shard-1-of-2.part <<'END'
import hashlib, struct, sys, zlib
h = hashlib.sha256(open(sys.argv[1], 'rb').read()).digest()
for path in sys.argv[2:]:
    b = bytearray(open(path, 'rb').read())
    pos = 12
    for k in range(2):  # version, hash name
        n, = struct.unpack('<I', b[pos:pos + 4])
        pos += 4 + n
    b[pos:pos + 32] = h
    pos += 32 + 8 + 36  # hash, seed, frames
    n, = struct.unpack('<I', b[pos:pos + 4])
    pos += 4 + n + 8  # params, shard I and N
    b[pos:pos + 4] = struct.pack('<I', zlib.crc32(bytes(b[:pos])))
    open(path.replace('two.', 'one.'), 'wb').write(b)
END
case_ "unused record" one.frac p/one.shard-0-of-2.part p/one.shard-1-of-2.part
