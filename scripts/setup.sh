#!/usr/bin/env bash
# Installs what building, running and testing ball_physics_sim needs on Debian 12, and the
# Debian packages given as arguments, as root or through sudo. Idempotent: a package already
# there is not fetched again.
set -euo pipefail

PACKAGES=(
  build-essential cmake pkg-config
  ros-core-dev catkin python3-catkin-pkg python3-rostest python3-rosunit
  libroscpp-dev librostest-dev libtf2-ros-dev libstd-srvs-dev
  libgeometry-msgs-dev libvisualization-msgs-dev libros-rosgraph-msgs-dev
  ros-message-generation ros-message-runtime python3-roslaunch rosbash
  python3-rospy python3-rosservice python3-rostopic python3-geometry-msgs python3-visualization-msgs
  python3-tf2-msgs python3-rosgraph-msgs python3-std-srvs
  libdynamic-reconfigure-config-init-mutex-dev python3-dynamic-reconfigure
  libinteractive-markers-dev
  libeigen3-dev libyaml-cpp-dev libgtest-dev googletest
  rviz
  # The rviz screenshot test: a virtual X display, screenshots, and the test's Python.
  xvfb imagemagick python3-yaml python3-rospkg
  # roslaunch resolves "localhost"; a minimal Debian has no /etc/hosts to do it.
  libnss-myhostname
  # The peers of bench/bench_engines.
  libbox2d-dev libchipmunk-dev
  "$@"
)

as_root() {
  if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi
}

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  as_root apt-get update
  as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends "${missing[@]}"
else
  echo "setup: every package is installed"
fi
