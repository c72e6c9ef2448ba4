#!/usr/bin/env bash
# Makes the docs' pictures (doc/images/ by default) from the current code: installs what is
# missing, builds, then runs sim_node and rviz on a virtual display (scripts/make_pictures.py).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/env.sh"
OUT_DIR="$(realpath -m "${1:-$REPO_DIR/doc/images}")"
PORT=11413  # its own master, away from a running simulator's

bash "$REPO_DIR/scripts/setup.sh" python3-matplotlib python3-rosbag
build_package "$BUILD_DIR" "$DEVEL_DIR"
set +u  # catkin's setup reads unset variables
source "$DEVEL_DIR/setup.bash"
set -u
export ROS_MASTER_URI="http://127.0.0.1:$PORT"
if rosnode list >/dev/null 2>&1; then
  echo "pictures: a ROS master already runs on port $PORT; stop it first" >&2
  exit 1
fi
roscore -p "$PORT" >/dev/null 2>&1 &
master=$!
trap 'kill $master 2>/dev/null; wait $master 2>/dev/null || true' EXIT
for _ in $(seq 60); do rosparam set /use_sim_time false 2>/dev/null && break; sleep 0.5; done
rosparam get /use_sim_time >/dev/null || { echo "pictures: roscore did not start" >&2; exit 1; }
# The bags plotted and the nodes' log stay in build/pictures/.
python3 "$REPO_DIR/scripts/make_pictures.py" "$OUT_DIR" "$BUILD_DIR/pictures"
ls -l "$OUT_DIR"
