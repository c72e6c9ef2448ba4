#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (and ASan + UBSan) and runs each for SECONDS seconds
# (default 60): fuzz_scene (the scene loader) and fuzz_world (the engine's step under random
# calls). They start from the corpus in test/fuzz/corpus/<target>/ (and the shipped scenes) and
# keep what they find new in build/fuzz/corpus/<target>/. A finding stops that fuzzer, keeps its
# input as build/fuzz/<target>-crash-* (or -timeout-, -oom-) and makes this script fail.
# Usage: bash scripts/fuzz.sh [SECONDS]
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/env.sh"
seconds="${1:-60}"

bash "$REPO_DIR/scripts/setup.sh" clang libclang-rt-14-dev
FUZZ_DIR="$BUILD_DIR/fuzz"
CC=clang CXX=clang++ configure_package "$FUZZ_DIR" "$FUZZ_DIR/devel" -DBALL_PHYSICS_SIM_FUZZ=ON
make -C "$FUZZ_DIR" -j"$(nproc)" fuzz_scene fuzz_world

status=0
for target in scene world; do
  seeds=("$REPO_DIR/test/fuzz/corpus/$target")
  if [ "$target" = scene ]; then seeds+=("$REPO_DIR/config/scenes"); fi
  mkdir -p "$FUZZ_DIR/corpus/$target"
  echo "fuzz.sh: fuzz_$target for $seconds s"
  # A step must never take seconds: -timeout makes a hang a finding.
  "$FUZZ_DIR/devel/lib/ball_physics_sim/fuzz_$target" -max_total_time="$seconds" -timeout=10 \
    -rss_limit_mb=4096 -print_final_stats=1 -artifact_prefix="$FUZZ_DIR/$target-" \
    "$FUZZ_DIR/corpus/$target" "${seeds[@]}" || status=1
done
exit "$status"
