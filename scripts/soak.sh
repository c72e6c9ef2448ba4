#!/usr/bin/env bash
# Soak test: runs sim_node (default scene) for SECONDS (default 600) while soak_client.py sends
# a few hundred mixed valid and invalid service calls a second and spawns up to MAX_BALLS
# (default 200, the node's ~max_balls). Records the node's resident memory and step rate every
# 10 s in build/soak/soak.csv and ends with a summary; fails if the node died or a call was
# not answered.
# Usage: bash scripts/soak.sh [SECONDS] [MAX_BALLS]
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/env.sh"
seconds="${1:-600}"
max_balls="${2:-200}"

bash "$REPO_DIR/scripts/setup.sh"
build_package "$BUILD_DIR" "$DEVEL_DIR"
set +u
source "$DEVEL_DIR/setup.bash"
set -u
# A master of its own, so that a running simulator is not disturbed.
export ROS_MASTER_URI=http://127.0.0.1:11412
out="$BUILD_DIR/soak"
mkdir -p "$out"
core="" node=""
trap 'kill $node $core 2>/dev/null || true' EXIT
roscore -p 11412 > "$out/roscore.log" 2>&1 &
core=$!
for _ in $(seq 60); do rosparam list > /dev/null 2>&1 && break; sleep 0.5; done
"$DEVEL_DIR/lib/ball_physics_sim/sim_node" _scene:=default _max_balls:="$max_balls" \
  > "$out/sim_node.log" 2>&1 &
node=$!
python3 "$REPO_DIR/scripts/soak_client.py" --seconds "$seconds" --node-pid "$node" \
  --csv "$out/soak.csv"
