# Sourced by the other scripts: the environment ROS tools need on this machine.
# Debian's ROS Python packages live in the system python; a pyenv python first in PATH
# would not find them.
export PATH="/usr/bin:/bin:$PATH"
# A fresh machine may resolve neither its hostname nor even "localhost" (a minimal Debian has
# no /etc/hosts): unless told otherwise, ROS talks over the loopback address itself.
if [ -z "${ROS_HOSTNAME:-}" ] && [ -z "${ROS_IP:-}" ]; then export ROS_IP=127.0.0.1; fi
export ROS_MASTER_URI="${ROS_MASTER_URI:-http://127.0.0.1:11311}"
REPO_DIR="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD_DIR="${BUILD_DIR:-$REPO_DIR/build}"
# The devel space lies beside build/, not in it: rosrun ignores executables below a package's
# build/ folder.
DEVEL_DIR="${DEVEL_DIR:-$REPO_DIR/devel}"

# configure_package BUILD_DIR DEVEL_DIR [CMAKE_ARGS...]: runs cmake for the package there.
configure_package() {
  local build_dir="$1" devel_dir="$2"
  shift 2
  cmake -S "$REPO_DIR" -B "$build_dir" -DPYTHON_EXECUTABLE=/usr/bin/python3 \
    -DCATKIN_DEVEL_PREFIX="$devel_dir" "$@"
}

# build_package BUILD_DIR DEVEL_DIR [CMAKE_ARGS...]: configures and builds the package there.
build_package() {
  configure_package "$@"
  make -C "$1" -j"$(nproc)"
}

# built_package: installs what is missing, builds the package and takes on its devel space's
# environment, for the scripts that run sim_node.
built_package() {
  bash "$REPO_DIR/scripts/setup.sh"
  build_package "$BUILD_DIR" "$DEVEL_DIR"
  set +u  # catkin's setup reads unset variables
  source "$DEVEL_DIR/setup.bash"
  set -u
}

# own_master PORT LOG: starts a roscore of its own on PORT, so that a running simulator is not
# disturbed, and waits until it answers; its pid is left in master_pid.
own_master() {
  export ROS_MASTER_URI="http://127.0.0.1:$1"
  roscore -p "$1" > "$2" 2>&1 &
  master_pid=$!
  for _ in $(seq 60); do rosparam list > /dev/null 2>&1 && return 0; sleep 0.5; done
  echo "roscore did not answer on port $1" >&2
  return 1
}
