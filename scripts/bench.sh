#!/usr/bin/env bash
# Installs what is missing (Box2D and Chipmunk included), builds, and runs the side-by-side
# benchmark: bash scripts/bench.sh [N ...] [--budget SECONDS] [--steps K] [--scene NAME ...]
# [--engine ours|Box2D|Chipmunk ...] [--write] (default: 1000 10000). With --write, the table
# the benchmark prints replaces the one between the markers <!-- bench:begin --> and
# <!-- bench:end --> in docs/benchmark.md and README.md, with Box2D v3's rows where
# BOX2D3_BENCH names a script that prints them.
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
# A table of some scenes, or some engines, would stand for all of them.
for arg in "${args[@]}"; do
  case "$arg" in
    --scene | --engine) echo "bench: --write takes every scene and engine, not $arg" >&2; exit 2 ;;
  esac
done

table="$(mktemp)"
trap 'rm -f "$table"' EXIT
"$bench" "${args[@]}" | tee "$table"
# What produced the table, then the table as printed.
python3 - "$table" "bench_engines ${args[*]}" "$(nproc)" \
  "$(git -C "$REPO_DIR" rev-parse --short HEAD)" "$REPO_DIR/docs/benchmark.md" \
  "$REPO_DIR/README.md" <<'PY'
import os
import pathlib
import re
import subprocess
import sys

table, command, cores, commit, *pages = sys.argv[1:]
# The table's lines alone (Chipmunk's debug build prints a banner among them).
lines = [line for line in open(table) if line.startswith("|")]
# Box2D v3 beside each of our rows, as many steps, where a script that prints its row in this
# format is named (BOX2D3_BENCH, e.g. ../shared/peers/box2d3-bench.sh): after its group.
# Its steps are no more than fit the benchmark's budget, at the pace of three.
peer = os.environ.get("BOX2D3_BENCH")
words = command.split()
budget = float(words[words.index("--budget") + 1]) if "--budget" in words else 60.0


def cells_of(line):
    return [c.strip() for c in line.strip("|\n").split("|")]


# Its rows, each with the balls awake at the end that it tells on stderr ("awake at the end:
# A of N"); none for a scene it does not know (it says "unknown scene").
def peer_rows(scene, n, steps):
    run = subprocess.run(["bash", peer, scene, n, str(steps)], text=True,
                         env=dict(os.environ, B3_VERBOSE="1"), stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE)
    if run.returncode != 0 and "unknown scene" in run.stderr:
        return []
    if run.returncode != 0:
        sys.stderr.write(run.stderr)
        run.check_returncode()
    awake = re.search(r"awake at the end: (\d+)", run.stderr)
    cell = f" {int(awake.group(1)):6d} |" if awake else "      - |"
    return [line + cell + "\n" for line in run.stdout.splitlines() if line.startswith("|")]


if peer:
    for k in reversed(range(len(lines))):
        cells = cells_of(lines[k])
        if len(cells) < 5 or cells[2] != "ours":
            continue
        scene, n = cells[0], cells[1]
        # (A pace printed as 0.000 ms, a tiny scene's, fits every step.)
        paced = peer_rows(scene, n, 3)
        if not paced:
            continue
        pace = max(float(cells_of(paced[0])[3]), 1e-3)
        row = peer_rows(scene, n, min(int(cells[4]), max(1, int(budget * 1000 / pace))))
        end = k + 1
        while end < len(lines) and cells_of(lines[end])[:2] == [scene, n]:
            end += 1
        lines[end:end] = row
        print("".join(row), end="")
rows = "".join(lines)
if peer:
    command += f"` and `{peer} SCENE N STEPS"
block = (f"<!-- bench:begin -->\n`{command}` at {commit}, {cores} cores, written by "
         f"`bash scripts/bench.sh --write`:\n\n{rows}<!-- bench:end -->")
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
