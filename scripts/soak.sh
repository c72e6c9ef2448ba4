#!/usr/bin/env bash
# Soak test: runs sim_node (default scene) for SECONDS (default 600) while soak_client.py sends
# a few hundred mixed valid and invalid service calls a second and spawns up to MAX_BALLS
# (default 200, the node's ~max_balls). Records the node's resident memory and step rate every
# 10 s in build/soak/soak.csv and ends with a summary; fails if the node died, a call was not
# answered or a 10 s window's real-time factor fell below 0.95.
# Usage: bash scripts/soak.sh [SECONDS] [MAX_BALLS]
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/env.sh"
seconds="${1:-600}"
max_balls="${2:-200}"

built_package
out="$BUILD_DIR/soak"
mkdir -p "$out"
master_pid="" node=""
trap 'kill $node $master_pid 2>/dev/null || true' EXIT
own_master 11412 "$out/roscore.log"
"$DEVEL_DIR/lib/ball_physics_sim/sim_node" _scene:=default _max_balls:="$max_balls" \
  > "$out/sim_node.log" 2>&1 &
node=$!
python3 "$REPO_DIR/scripts/soak_client.py" --seconds "$seconds" --node-pid "$node" \
  --csv "$out/soak.csv"
