#!/bin/sh
# prefixes.sh — every external symbol of interp/ carries one of its modules'
# prefixes (docs/internals.md, "Layers"), so a name tells its layer and no
# interp/ name borrows a runtime prefix (ifs_, mesh_, fit_, png_, rt_ …).
# Reads the objects beside the frac on PATH (build/interp/*.o, or
# build-asan/interp/*.o under make asan) with nm; prints the offenders and
# exits 1, or "prefixes: ok N symbols" and 0. tests/cli/interp_prefixes.cli.
set -u
frac=$(command -v frac) || { echo "prefixes: no frac on PATH"; exit 1; }
dir=$(dirname "$frac")/interp
command -v nm >/dev/null 2>&1 || { echo "prefixes: skipped (nm, from binutils, is not installed)"; exit 0; }
set -- "$dir"/*.o
[ -f "$1" ] || { echo "prefixes: no objects in $dir"; exit 1; }
# the modules' prefixes, as docs/internals.md lists them
ok='^(lex|parse|resolve|check|compile|eval|val|interp|mem|err|diag|cstack|session|repl|contract|builtin|lang|bind|cli|recipe|report|shard|watch)_'
n=0 bad=0
for o in "$@"; do
    for s in $(nm -g --defined-only "$o" | awk 'NF == 3 { print $3 }'); do
        n=$((n + 1))
        case $s in
        main | __*) continue ;; # main, and what the compiler adds (ASan's __odr_asan.NAME)
        esac
        if ! echo "$s" | grep -Eq "$ok"; then
            echo "prefixes: $(basename "$o" .o).c exports '$s' without a module prefix"
            bad=1
        fi
    done
done
[ "$n" -gt 100 ] || { echo "prefixes: only $n symbols read from $dir (nm failed?)"; exit 1; }
[ "$bad" = 0 ] || exit 1
echo "prefixes: ok $n symbols"
