# recipe.sh — sourced (`. "$here/recipe.sh"`) by the tests that run a block
# of docs/scale.md as written: mpi.sh, parallel.sh, slurm.sh and
# frames_recipe.sh. They set `frac` (the binary under test) and `here`
# (tests/shard, absolute) first.
#
#   recipe_setup NAME  makes a fresh folder (removed at exit) the current
#                      one and puts the frac under test first on PATH as
#                      `frac`: the blocks call `frac`; $tmp names the folder
#   recipe_block WORDS prints the ```sh block after the first line of
#                      docs/scale.md holding WORDS (its marker names the test)
#   recipe_parts N     whether parts/ holds scene.shard-I-of-N.part for every
#                      I < N and nothing else; if not, prints what is wrong
#                      and fails
#   recipe_same A B    whether folders A and B hold the same files, byte for
#                      byte; if not, prints what differs and fails

recipe_setup() {
    tmp=$(mktemp -d "${TMPDIR:-/tmp}/frac-$1-XXXXXX") || exit 1
    trap 'rm -rf "$tmp"' EXIT
    bin=$(mktemp -d "$tmp/bin-XXXXXX") && ln -s "$(command -v "$frac")" "$bin/frac" || exit 1
    PATH=$bin:$PATH
    export PATH
    cd "$tmp" || exit 1
}

recipe_block() {
    awk -v m="$1" 'index($0, m) { on = 1; next } on && /^```sh/ { inb = 1; next }
         inb && /^```/ { exit } inb { print }' "$here/../../docs/scale.md"
}

recipe_parts() {
    i=0
    while [ "$i" -lt "$1" ]; do
        [ -f "parts/scene.shard-$i-of-$1.part" ] || { echo "no part of shard $i of $1"; return 1; }
        i=$((i + 1))
    done
    [ "$(ls parts | wc -l)" -eq "$1" ] || { echo "parts/ holds $(ls parts | tr '\n' ' ')"; return 1; }
}

recipe_same() {
    if [ "$(ls "$1")" != "$(ls "$2")" ]; then
        echo "$2/ holds $(ls "$2" | tr '\n' ' '), $1/ $(ls "$1" | tr '\n' ' ')"
        return 1
    fi
    for f in $(ls "$1"); do
        cmp -s "$1/$f" "$2/$f" || { echo "$f differs"; return 1; }
    done
}
