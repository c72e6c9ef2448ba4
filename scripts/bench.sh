#!/usr/bin/env bash
# Installs what is missing (Box2D and Chipmunk included), builds, and runs the side-by-side
# benchmark: bash scripts/bench.sh [N ...] [--budget SECONDS] [--scene NAME ...] [--write]
# (default: 1000 10000). With --write, the table the benchmark prints replaces the one between
# the markers <!-- bench:begin --> and <!-- bench:end --> in docs/benchmark.md and README.md.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/env.sh"

write=false
args=()
for arg in "$@"; do
  if [ "$arg" = --write ]; then write=true; else args+=("$arg"); fi
done
case "${args[0]:-}" in ""|--*) args=(1000 10000 "${args[@]}") ;; esac

bash "$REPO_DIR/scripts/setup.sh"
build_package "$BUILD_DIR" "$DEVEL_DIR"
bench="$DEVEL_DIR/lib/ball_physics_sim/bench_engines"
if ! $write; then exec "$bench" "${args[@]}"; fi
# A table of some scenes would stand for all of them.
for arg in "${args[@]}"; do
  if [ "$arg" = --scene ]; then echo "bench: --write takes every scene, not --scene" >&2; exit 2; fi
done

table="$(mktemp)"
trap 'rm -f "$table"' EXIT
"$bench" "${args[@]}" | tee "$table"
# What produced the table, then the table as printed.
python3 - "$table" "bench_engines ${args[*]}" "$(nproc)" \
  "$(git -C "$REPO_DIR" rev-parse --short HEAD)" "$REPO_DIR/docs/benchmark.md" \
  "$REPO_DIR/README.md" <<'PY'
import pathlib
import re
import sys

table, command, cores, commit, *pages = sys.argv[1:]
block = (f"<!-- bench:begin -->\n`{command}` at {commit}, {cores} cores, written by "
         f"`bash scripts/bench.sh --write`:\n\n{pathlib.Path(table).read_text()}<!-- bench:end -->")
written = {}
for page in map(pathlib.Path, pages):
    written[page], count = re.subn(r"<!-- bench:begin -->.*?<!-- bench:end -->",
                                   lambda _: block, page.read_text(), flags=re.S)
    if count != 1:
        sys.exit(f"bench: {page} needs one <!-- bench:begin --> ... <!-- bench:end --> block")
for page, text in written.items():
    page.write_text(text)
    print(f"bench: table written to {page}")
PY
