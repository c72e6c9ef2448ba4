#!/usr/bin/env bash
# Installs what is missing, builds, and runs the simulator (roslaunch starts its own master).
# Arguments go to roslaunch, e.g. `scene:=resting rviz:=true`.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/env.sh"

bash "$REPO_DIR/scripts/setup.sh"
build_package "$BUILD_DIR" "$DEVEL_DIR"
set +u  # catkin's setup scripts read unset variables
source "$DEVEL_DIR/setup.bash"
set -u
cat <<MSG

ball_physics_sim is starting. In another terminal:
  cd $REPO_DIR && source scripts/env.sh && source devel/setup.bash
  rosservice call /fire "{}"                  # fire the first launcher
  rostopic echo /contacts                     # every impact
  rviz -d config/sim.rviz                     # or start with: bash scripts/run.sh rviz:=true

MSG
exec roslaunch ball_physics_sim sim.launch "$@"
