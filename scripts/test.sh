#!/usr/bin/env bash
# Installs what is missing, builds, runs every unit test, rostest and the docs test, then builds
# again with AddressSanitizer and UndefinedBehaviorSanitizer and runs the tests that exercise
# memory and undefined behaviour once more (SANITIZED_TESTS). Ends with the slowest tests and
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

# run_tests BUILD_DIR [TARGET...]: those catkin test targets of that build (all by default);
# catkin's targets keep going past failing tests, the summary below decides.
run_tests() {
  local build_dir="$1"
  shift
  rm -rf "$build_dir/test_results"
  make -C "$build_dir" -j"$(nproc)" tests
  make -C "$build_dir" -j1 "${@:-run_tests}"
}

# Under the sanitizers: every engine unit test and fuzz corpus replay (the engine's memory and
# arithmetic, every path of it), and the rostests that call every service and parameter of the
# node with good and bad input. The scene rostests run the same node code on other scenes, whose
# engine paths the engine tests take; they run once, above.
SANITIZED_TESTS=(run_tests_ball_physics_sim_gtest
                 run_tests_ball_physics_sim_rostest_test_interface.test
                 run_tests_ball_physics_sim_rostest_test_load_scene.test
                 run_tests_ball_physics_sim_rostest_test_limits.test
                 run_tests_ball_physics_sim_rostest_test_contacts.test
                 run_tests_ball_physics_sim_rostest_test_reconfigure.test
                 run_tests_ball_physics_sim_rostest_test_resting_balls.test)

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
  run_tests "$SANITIZE_DIR" "${SANITIZED_TESTS[@]}"

python3 "$REPO_DIR/scripts/summarize_tests.py" "$BUILD_DIR/test_results" \
  "$SANITIZE_DIR/test_results" --sanitizer-reports "$REPORTS" --slowest 10
