#!/bin/sh
# merge_args.sh — tests/cli/shard_merge_args.cli: prints what merge's script prints.
set -u
frac=${FRAC:-frac}
tmp=$(mktemp -d "${TMPDIR:-/tmp}/frac-args-XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT
"$frac" run -q --shard 0/1 -o "$tmp" "$(dirname "$0")/args.frac" || exit 1
"$frac" merge -q -o "$tmp" "$(dirname "$0")/args.frac" "$tmp/args.shard-0-of-1.part"
