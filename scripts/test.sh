#!/usr/bin/env bash
# Installs what is missing, builds, runs every unit test and rostest, and ends with
# "N passed, N failed". Exits non-zero on any failure.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/env.sh"

bash "$REPO_DIR/scripts/setup.sh"
build_package
rm -rf "$BUILD_DIR/test_results"
# run_tests keeps going past failing tests; the summary below decides.
make -C "$BUILD_DIR" -j1 run_tests
python3 "$REPO_DIR/scripts/summarize_tests.py" "$BUILD_DIR/test_results"
