#!/usr/bin/env bash
# Installs what is missing, builds, runs every unit test and rostest, then builds again with
# AddressSanitizer and UndefinedBehaviorSanitizer and runs them all once more. Ends with
# "N passed, N failed" (a sanitizer report counts as a failure); exits non-zero on any failure.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/env.sh"

# build_for_tests BUILD_DIR DEVEL_DIR [CMAKE_ARGS...]: builds, then configures once more: catkin
# caches the tests' environment when it configures, and only once built does the devel space
# hold the generated Python messages that the Python rostest imports.
build_for_tests() {
  build_package "$@"
  configure_package "$@" >/dev/null
}

# run_tests BUILD_DIR: every test of that build; run_tests keeps going past failing tests, the
# summary below decides.
run_tests() {
  rm -rf "$1/test_results"
  make -C "$1" -j1 run_tests
}

bash "$REPO_DIR/scripts/setup.sh"
build_for_tests "$BUILD_DIR" "$DEVEL_DIR"
run_tests "$BUILD_DIR"

# Its devel space stays inside build/, where rosrun does not look for executables.
SANITIZE_DIR="$BUILD_DIR/sanitize"
REPORTS="$SANITIZE_DIR/sanitizer_reports"
build_for_tests "$SANITIZE_DIR" "$SANITIZE_DIR/devel" -DBALL_PHYSICS_SIM_SANITIZE=ON
rm -rf "$REPORTS" && mkdir -p "$REPORTS"
# Reports go to files: sim_node runs under roslaunch, whose output no test reads.
ASAN_OPTIONS="log_path=$REPORTS/asan:detect_leaks=1" \
UBSAN_OPTIONS="log_path=$REPORTS/ubsan:print_stacktrace=1" \
  run_tests "$SANITIZE_DIR"

python3 "$REPO_DIR/scripts/summarize_tests.py" "$BUILD_DIR/test_results" \
  "$SANITIZE_DIR/test_results" --sanitizer-reports "$REPORTS"
