# Sourced by the other scripts: the environment ROS tools need on this machine.
# Debian's ROS Python packages live in the system python; a pyenv python first in PATH
# would not find them.
export PATH="/usr/bin:/bin:$PATH"
# A fresh machine's hostname may not resolve; everything here talks over loopback.
export ROS_HOSTNAME="${ROS_HOSTNAME:-localhost}"
REPO_DIR="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD_DIR="${BUILD_DIR:-$REPO_DIR/build}"

build_package() {
  cmake -S "$REPO_DIR" -B "$BUILD_DIR" -DPYTHON_EXECUTABLE=/usr/bin/python3
  make -C "$BUILD_DIR" -j"$(nproc)"
}
