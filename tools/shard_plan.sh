#!/bin/sh
# shard_plan.sh [FRAC [EXAMPLE.frac…]] — which engine calls of every
# examples/*.frac (or of the EXAMPLEs given) a shard splits, and which it
# computes fully: the rows of the table "Per example" of docs/scale.md
# (tests/shard/plan_doc.sh checks them). Runs each example at its default
# params as shard 0 of 7 (`frac run --shard 0/7`, two threads), reads its
# part with an independent reader (python3: tests/shard/part.py) and prints
# one row an example:
#   | `NAME` | CALLS | KIND (K chunks), … | `BUILTIN` (line L): WHY; … | `BUILTIN`, … |
# the engine calls the evaluation made; the split ones from the part's
# records, by kind with their chunk counts (at most that many shards share
# a call); the ones computed fully in every shard from frac's notes (each
# names the call, where it was made and why its result must be whole); and
# the builtins of the script that make no engine call at all, so are never
# split (iterate/draw, the IST, … : a fixed list, found in the
# script's text; docs/scale.md, "What is split", says why).
set -u
frac=${1:-build/frac}
[ $# -gt 0 ] && shift
[ $# -gt 0 ] || set -- examples/*.frac
here=$(cd "$(dirname "$0")/../tests/shard" && pwd)
tmp=$(mktemp -d "${TMPDIR:-/tmp}/frac-plan-XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT
for s in "$@"; do
    name=$(basename "$s" .frac)
    rm -rf "$tmp/p"
    if ! "$frac" run --threads 2 --shard 0/7 -o "$tmp/p" "$s" >/dev/null 2>"$tmp/err"; then
        echo "$name | FAILED: $(head -n 1 "$tmp/err")"
        continue
    fi
    python3 - "$name" "$tmp/p/$name.shard-0-of-7.part" "$tmp/err" "$here" "$s" <<'END'
import re, sys
name, path, err, here, script = sys.argv[1:6]
sys.dont_write_bytecode = True  # no __pycache__ in the tree
sys.path.insert(0, here)
import part
p = part.read(path)
calls = p.calls
split = {}
for r in p.records:
    split.setdefault(r.call, (r.kind, r.chunks))
# the full calls: grouped by where they were made and why
full = {}
for line in open(err):
    m = re.match(r'frac: note: engine call (\d+) \(at (.*):(\d+):(\d+)\) is computed fully in every shard: its result (.*)$', line)
    if not m:
        continue
    path, l, c, why = m.group(2), int(m.group(3)), int(m.group(4)), m.group(5)
    src = open(path).read().split('\n')[l - 1]
    callee = re.match(r'[A-Za-z_]\w*', src[c - 1:]).group(0)
    why = re.sub(r' at [^ ]*:\d+:\d+$', '', why)
    why = re.sub(r'^is passed to print$', 'printed', why)
    why = re.sub(r'^is passed to (\w+)$', r'passed to `\1`', why)
    why = re.sub(r'^is inspected \(\.(\w+)\)$', r'its `.\1` read', why)
    why = re.sub(r'^is ', '', why)
    full.setdefault((l, callee, why), []).append(m.group(1))
fulls = ['`%s` (line %d%s): %s' % (callee, l, ', %d calls' % len(v) if len(v) > 1 else '', why)
         for (l, callee, why), v in sorted(full.items())]
# the engines that make no engine call: never split (docs/scale.md, "What is split")
never = ['iterate', 'draw', 'ist', 'ist_lists', 'ist_inv', 'wrinkly_draw',
         'wrinkly_points', 'fractal', 'fit', 'tiling', 'tile']
code = '\n'.join(l.split('#')[0] for l in open(script))
used = [n for n in never if re.search(r'\b%s\(' % n, code)]
kinds = {}
for call, (kind, chunks) in sorted(split.items()):
    kinds.setdefault(kind, []).append(chunks)
def chunks(v):
    if len(set(v)) == 1:
        return '%d chunk%s%s' % (v[0], 's' if v[0] > 1 else '', ' each' if len(v) > 1 else '')
    return '/'.join(str(c) for c in v) + ' chunks'
sp = ', '.join('%s%s (%s)' % (k, ' ×%d' % len(v) if len(v) > 1 else '', chunks(v)) for k, v in kinds.items())
print('| `%s` | %d | %s | %s | %s |' % (name, calls, sp or '—', '; '.join(fulls) or '—',
      ', '.join('`%s`' % n for n in used) or '—'))
END
done
