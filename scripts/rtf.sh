#!/usr/bin/env bash
# Real-time factor of sim_node with many balls: runs it (its defaults: steps of 1/120 s at
# real-time factor 1, `balls` and tf at 60 Hz, `markers` at 30 Hz) on elastic billiards of N
# balls (default 1000) for SECONDS of wall time (default 60) while rtf_client.py subscribes to
# `balls` and `markers`, as rviz would, and reports the sim time kept, the topic rates and the
# node's CPU use. Usage: bash scripts/rtf.sh [N] [SECONDS]
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/env.sh"
balls="${1:-1000}"
seconds="${2:-60}"

built_package
out="$BUILD_DIR/rtf"
mkdir -p "$out"
python3 "$REPO_DIR/scripts/rtf_client.py" --write-scene "$balls" > "$out/billiards.yaml"
master_pid="" node=""
trap 'kill $node $master_pid 2>/dev/null || true' EXIT
own_master 11413 "$out/roscore.log"
"$DEVEL_DIR/lib/ball_physics_sim/sim_node" _scene_file:="$out/billiards.yaml" \
  _max_balls:="$balls" > "$out/sim_node.log" 2>&1 &
node=$!
python3 "$REPO_DIR/scripts/rtf_client.py" --seconds "$seconds" --node-pid "$node"
