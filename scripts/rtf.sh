#!/usr/bin/env bash
# Real-time factor of sim_node with many balls. sim_node runs with its defaults (steps of 1/120 s
# at real-time factor 1, `balls` and tf at 60 Hz, `markers` at 30 Hz) under a master of its own,
# while rtf_client.py subscribes to `balls` and `markers`, as rviz would, and reports the sim time
# kept, the topic rates and the node's CPU use. Output also in build/rtf/<mode>.log.
#
# Usage:
#   bash scripts/rtf.sh [N] [SECONDS]     elastic billiards of N balls (default 1000) for SECONDS
#                                         of wall time (default 60): one figure for the whole run
#   bash scripts/rtf.sh rain [SECONDS]    the default scene as sim.launch starts it (/use_sim_time
#                                         true, headless), ~max_balls 1000; balls of radius 0.1 m
#                                         rain into the top of its box 10 times a second until
#                                         1000 are there; figures of every 10 s window for SECONDS
#                                         (default 120), the worst window and PASS or FAIL against
#                                         the target (real-time factor >= 0.95, `balls` at 60 Hz
#                                         and every awake ball moving, in every window)
# The exit status is not the verdict: it is non-zero only if the tool failed (no state arrived,
# the node died, a ball refused for another reason than its place).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/env.sh"
mode=billiards
if [ "${1:-}" = rain ]; then
  mode=rain
  shift
fi
max_args=2
[ "$mode" = billiards ] || max_args=1
for arg in "$@"; do
  [[ "$arg" =~ ^[0-9]+(\.[0-9]+)?$ ]] || { echo "rtf.sh: '$arg' is not a number; usage in $0" >&2; exit 2; }
done
[ $# -le "$max_args" ] || { echo "rtf.sh: too many arguments; usage in $0" >&2; exit 2; }
if [ "$mode" = rain ]; then
  balls=1000
  seconds="${1:-120}"
else
  balls="${1:-1000}"
  seconds="${2:-60}"
fi

built_package
out="$BUILD_DIR/rtf"
mkdir -p "$out"
master_pid="" node=""
trap 'kill $node $master_pid 2>/dev/null || true' EXIT
own_master 11413 "$out/roscore.log"
if [ "$mode" = rain ]; then
  scene="$REPO_DIR/config/scenes/default.yaml"
  rosparam set /use_sim_time true
  "$DEVEL_DIR/lib/ball_physics_sim/sim_node" __name:=sim_node _scene_file:="$scene" \
    _max_balls:="$balls" > "$out/sim_node.log" 2>&1 &
  node=$!
  python3 "$REPO_DIR/scripts/rtf_client.py" --rain "$scene" --balls "$balls" \
    --seconds "$seconds" --node-pid "$node" | tee "$out/rain.log"
else
  python3 "$REPO_DIR/scripts/rtf_client.py" --write-scene "$balls" > "$out/billiards.yaml"
  "$DEVEL_DIR/lib/ball_physics_sim/sim_node" _scene_file:="$out/billiards.yaml" \
    _max_balls:="$balls" > "$out/sim_node.log" 2>&1 &
  node=$!
  python3 "$REPO_DIR/scripts/rtf_client.py" --seconds "$seconds" --node-pid "$node" \
    | tee "$out/billiards.log"
fi
