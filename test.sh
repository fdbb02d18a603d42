#!/usr/bin/env bash
# Installs what is missing, builds Release into build/ and runs the whole test
# suite with CTest.
set -euo pipefail
cd "$(dirname "$0")"
./scripts/setup.sh
cd build
ctest --output-on-failure -j "${DIFFPD_TEST_JOBS:-$(nproc)}" "$@"
