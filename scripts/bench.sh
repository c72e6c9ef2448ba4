#!/usr/bin/env bash
# Installs what is missing (Box2D and Chipmunk included), builds, and runs the side-by-side
# benchmark: bash scripts/bench.sh [N ...] [--budget SECONDS]   (default: 1000 10000)
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/env.sh"

bash "$REPO_DIR/scripts/setup.sh"
build_package "$BUILD_DIR" "$DEVEL_DIR"
case "${1:-}" in ""|--*) set -- 1000 10000 "$@" ;; esac
exec "$DEVEL_DIR/lib/ball_physics_sim/bench_engines" "$@"
