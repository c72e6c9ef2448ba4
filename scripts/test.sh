#!/usr/bin/env bash
# Installs what is missing, builds in a catkin workspace with catkin_make, runs every unit test,
# rostest and the docs test, installs with `catkin_make install` and runs sim.launch from the
# install space alone (test/test_install_space.py), then builds again with AddressSanitizer and
# UndefinedBehaviorSanitizer and runs the tests that exercise memory and undefined behaviour
# once more. Ends with the slowest tests and "N passed, N failed" (a sanitizer report counts
# as a failure); exits non-zero on any failure.
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
# arithmetic, every path of it) but the long physics runs below, and the rostests that call
# every service and parameter of the node with good and bad input (the sanitized build defines
# no others: CMakeLists.txt). The long runs take the paths of shorter tests for minutes more:
# a thousand-ball pile resting for a minute, hundreds of crowded random boxes, 150 balls
# raining into a box, a 200-ball pile landing beside a bouncing ball (the 64-ball pile takes
# its settles), the ropes scene swinging for a minute (the corpus replays run it).
LONG_PHYSICS_RUNS="World.TheBenchmarksPileOfAThousandBalls*:World.CrowdedRandomBoxes*"
LONG_PHYSICS_RUNS+=":World.BallsRainingIntoTheDefaultBox*"
LONG_PHYSICS_RUNS+=":World.AnElasticBallBouncingFarFromASettlingPile*"
LONG_PHYSICS_RUNS+=":Rope.TheRopesScenesCradlePassesItsSwingOn*"

bash "$REPO_DIR/scripts/setup.sh"
# With line tables only (-g1): GCC's code does not depend on -g, so this is RelWithDebInfo's
# code, and full debug information took a third of the compile time of the heaviest files.
build_for_tests "$BUILD_DIR" "$DEVEL_DIR" -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG"
run_tests "$BUILD_DIR"

# The install space alone, in an environment with nothing else sourced: sim.launch from it must
# answer fire and the newer services. Its JUnit file goes with the others; a run that left none
# fails here.
catkin_make_package "$BUILD_DIR" "$DEVEL_DIR" -j"$(nproc)" install > "$BUILD_DIR/install.log" ||
  { tail -n 40 "$BUILD_DIR/install.log"; exit 1; }
install_result="$BUILD_DIR/test_results/ball_physics_sim/rosunit-install_space.xml"
env -i HOME="$HOME" PATH=/usr/bin:/bin ROS_IP=127.0.0.1 ROS_HOME="$BUILD_DIR/install_check" \
  bash -c 'source "$1/setup.bash" && exec python3 "$2" --install-space "$1" "--gtest_output=xml:$3"' \
  _ "$INSTALL_DIR" "$REPO_DIR/test/test_install_space.py" "$install_result" || [ -f "$install_result" ]

# Its devel space stays inside build/, where rosrun does not look for executables.
SANITIZE_DIR="$BUILD_DIR/sanitize"
REPORTS="$SANITIZE_DIR/sanitizer_reports"
build_for_tests "$SANITIZE_DIR" "$SANITIZE_DIR/devel" -DBALL_PHYSICS_SIM_SANITIZE=ON
rm -rf "$REPORTS" && mkdir -p "$REPORTS"
# Reports go to files: sim_node runs under roslaunch, whose output no test reads.
ASAN_OPTIONS="log_path=$REPORTS/asan:detect_leaks=1" \
UBSAN_OPTIONS="log_path=$REPORTS/ubsan:print_stacktrace=1" \
GTEST_FILTER="-$LONG_PHYSICS_RUNS" run_tests "$SANITIZE_DIR"

python3 "$REPO_DIR/scripts/summarize_tests.py" "$BUILD_DIR/test_results" \
  "$SANITIZE_DIR/test_results" --sanitizer-reports "$REPORTS" --slowest 10
