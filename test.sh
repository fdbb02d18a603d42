#!/usr/bin/env bash
# Installs what is missing, builds Release into build/ and runs the whole test
# suite with CTest; then every file reader's fuzz harness for a fixed time
# (scripts/fuzz.sh, in build-fuzz/; DIFFPD_EDGE_CHECKS=0 skips it); then the
# core tests (the library's, the rollout core's and the optimiser adapters')
# again under AddressSanitizer and UndefinedBehaviorSanitizer
# (scripts/sanitize.sh, in build-sanitize/; DIFFPD_SANITIZE=0 skips it,
# DIFFPD_SANITIZE_SCOPE=all runs the whole suite there, a second full build
# that would take CI past its time bound). Extra arguments go to the Release
# suite's ctest.
set -euo pipefail
cd "$(dirname "$0")"
./scripts/setup.sh
(cd build && ctest --output-on-failure -j "${DIFFPD_TEST_JOBS:-$(nproc)}" "$@")
if [ "${DIFFPD_EDGE_CHECKS:-1}" != 0 ]; then
  ./scripts/fuzz.sh
fi
if [ "${DIFFPD_SANITIZE:-1}" != 0 ]; then
  ./scripts/sanitize.sh
fi
