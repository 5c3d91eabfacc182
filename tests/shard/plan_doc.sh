#!/bin/sh
# plan_doc.sh — the table "Per example" of docs/scale.md is what
# tools/shard_plan.sh prints (tests/cli/shard_plan_doc.cli): it has one row
# for every examples/*.frac and no other, and for every example but the
# slow ones below, its row equals the row the tool prints now (the tool
# runs the example as shard 0 of 7 at its default params and reads its
# part). The slow ones take 3 to 24 s each here, their rows are checked
# for presence only: regenerate them by hand (`sh tools/shard_plan.sh`).
# Prints "plan: …"; exits non-zero on a failure. Needs python3 (the tool's
# part reader): "plan: skipped (…)" without it.
set -u
frac=${FRAC:-frac}
here=$(cd "$(dirname "$0")" && pwd)
root=$here/../..
slow="fit_leaf hypertexture wrinkly_fig6 wrinkly_fig11"
if ! command -v python3 >/dev/null 2>&1; then
    echo "plan: skipped (python3 is not installed to read the parts)"
    exit 0
fi
tmp=$(mktemp -d "${TMPDIR:-/tmp}/frac-plan-doc-XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT
fail() { echo "plan: FAIL ($*)"; exit 1; }
cd "$root" || exit 1
# the table's rows: the lines "| `NAME` |" of the section "## Per example"
awk '/^## / { on = ($0 == "## Per example") } on && /^\| `/' docs/scale.md >"$tmp/doc"
sed 's/^| `\([^`]*\)`.*/\1/' "$tmp/doc" >"$tmp/doc.names"
ls examples/*.frac | sed 's|^examples/||; s|\.frac$||' >"$tmp/names"
sort "$tmp/doc.names" | cmp -s - "$tmp/names" ||
    fail "the rows are not one an example: $(sort "$tmp/doc.names" | diff - "$tmp/names" | grep '^[<>]' | tr '\n' ' ')"
run=
for n in $(cat "$tmp/names"); do
    case " $slow " in *" $n "*) ;; *) run="$run examples/$n.frac" ;; esac
done
sh tools/shard_plan.sh "$(command -v "$frac")" $run >"$tmp/tool" || fail "tools/shard_plan.sh failed"
grep -v -F "$(for n in $slow; do printf '| `%s` |\n' "$n"; done)" "$tmp/doc" >"$tmp/doc.run"
diff "$tmp/doc.run" "$tmp/tool" >"$tmp/diff" || fail "rows differ from the tool's: $(grep '^[<>]' "$tmp/diff" | head -n 4 | tr '\n' ' ')"
echo "plan: $(wc -l <"$tmp/names") examples, one row each; $(wc -l <"$tmp/tool") rows as tools/shard_plan.sh prints them, $(echo $slow | wc -w) not re-run (slow)"
