#!/usr/bin/env bash
# The test command of the README: installs what is missing, builds (warnings are
# errors) and runs every test: unit tests, bad-input tests and the coarse validation
# cases. Usage: scripts/test.sh [extra cmake options...]; BUILD=dir picks the folder.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
BUILD=${BUILD:-build}
cmake -S . -B "$BUILD" -DCMAKE_BUILD_TYPE=Release -DRHOD_WERROR=ON "$@" >/dev/null
cmake --build "$BUILD" -j"$(nproc)"
cd "$BUILD"
# RHOD_CTEST_EXCLUDE: a regular expression of tests to leave out (.ci/run's slower builds)
ctest --output-on-failure -j1 ${RHOD_CTEST_EXCLUDE:+-E "$RHOD_CTEST_EXCLUDE"}
