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

# The Slurm recipe in the current folder (slurm.sh emulated, slurm_real.sh
# real): scene.frac and its single run in single/, render.sbatch and
# submit.sh as docs/scale.md writes them; sets n, the array's size (the
# recipe's N). On a doc without them, the caller's fail.
recipe_slurm_files() {
    cp "$here/small.frac" scene.frac || exit 1
    frac -q -o single scene.frac || exit 1
    recipe_block "tests/shard/slurm.sh runs this block as render.sbatch" >render.sbatch
    recipe_block "tests/shard/slurm.sh runs these two lines" >submit.sh
    grep -q '^#SBATCH --array=' render.sbatch || fail "no job array script in docs/scale.md"
    grep -q '^sbatch ' submit.sh || fail "no sbatch lines in docs/scale.md"
    range=$(sed -n 's/^#SBATCH --array=\([0-9]*-[0-9]*\)$/\1/p' render.sbatch)
    [ -n "$range" ] || fail "the array is not A-B"
    n=$((${range#*-} - ${range%-*} + 1))
}
