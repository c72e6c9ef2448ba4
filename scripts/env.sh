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

# The package builds as users build it, in a catkin workspace with Debian's catkin_make: the
# workspace's src/ball_physics_sim links to this repository, its build spaces are BUILD_DIR (and
# the sanitizer's and fuzzer's below it), its devel space DEVEL_DIR, and `catkin_make install`
# fills INSTALL_DIR.
WORKSPACE_DIR="$BUILD_DIR/workspace"
INSTALL_DIR="$WORKSPACE_DIR/install"

# catkin_make_package BUILD_DIR DEVEL_DIR [CMAKE_ARGS...] [MAKE_TARGETS...]: catkin_make in the
# workspace, with that build and devel space.
catkin_make_package() {
  local build_dir="$1" devel_dir="$2"
  shift 2
  # Each top-level entry is linked but build/ and devel/: a link to the whole repository would
  # hold itself (build/workspace/...), and roslaunch, finding a node, walks a package's folder
  # following links.
  local package="$WORKSPACE_DIR/src/ball_physics_sim" entry
  mkdir -p "$package"
  for entry in "$REPO_DIR"/*; do
    case "${entry##*/}" in build | devel) ;; *) ln -sfn "$entry" "$package/" ;; esac
  done
  find "$package" -maxdepth 1 -xtype l -delete  # links to entries gone
  # A build space configured from the repository itself (before it was a workspace) starts anew.
  if [ -f "$build_dir/CMakeCache.txt" ] &&
     ! grep -qx "CMAKE_HOME_DIRECTORY:INTERNAL=$WORKSPACE_DIR/src" "$build_dir/CMakeCache.txt"; then
    rm -rf "$build_dir/CMakeCache.txt" "$build_dir/CMakeFiles"
  fi
  /usr/bin/catkin_make -C "$WORKSPACE_DIR" --build "$build_dir" \
    -DPYTHON_EXECUTABLE=/usr/bin/python3 -DCATKIN_DEVEL_PREFIX="$devel_dir" "$@"
}

# configure_package BUILD_DIR DEVEL_DIR [CMAKE_ARGS...]: runs cmake for the package there.
configure_package() {
  catkin_make_package "$@" --force-cmake cmake_check_build_system
}

# build_package BUILD_DIR DEVEL_DIR [CMAKE_ARGS...]: configures and builds the package there.
build_package() {
  catkin_make_package "$@" -j"$(nproc)"
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
