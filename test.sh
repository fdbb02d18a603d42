#!/usr/bin/env bash
# Installs what is missing, builds Release into build/ and runs the whole test
# suite with CTest; then every file reader's fuzz harness for a fixed time
# (scripts/fuzz.sh, in build-fuzz/; DIFFPD_EDGE_CHECKS=0 skips it); then the
# core tests (the library's, the rollout core's and the optimiser adapters')
# again under AddressSanitizer and UndefinedBehaviorSanitizer
# (scripts/sanitize.sh, in build-sanitize/; DIFFPD_SANITIZE_SCOPE=all runs the
# whole suite there, a second full build).
#
# The sanitized tests are a second build and take about 1.3 times as long as
# everything before them. DIFFPD_SANITIZE chooses:
#   auto (default)  run them when the time so far times 2.3 fits within
#                   DIFFPD_TIME_BUDGET_MINUTES (default 45); otherwise say so
#                   and skip them, so that the command ends within the budget
#                   on a slow machine;
#   1               always run them;  0  never.
# Extra arguments go to the Release suite's ctest.
set -euo pipefail
cd "$(dirname "$0")"

sanitize="${DIFFPD_SANITIZE:-auto}"
budget_min="${DIFFPD_TIME_BUDGET_MINUTES:-45}"
case "$sanitize" in
  auto | 0 | 1) ;;
  *)
    echo "test.sh: DIFFPD_SANITIZE = '$sanitize' is invalid: must be auto, 0 or 1" >&2
    exit 2
    ;;
esac
if ! [[ "$budget_min" =~ ^[1-9][0-9]*$ ]]; then
  echo "test.sh: DIFFPD_TIME_BUDGET_MINUTES = '$budget_min' is invalid: must be a positive whole number" >&2
  exit 2
fi

start=$SECONDS
./scripts/setup.sh
(cd build && ctest --output-on-failure -j "${DIFFPD_TEST_JOBS:-$(nproc)}" "$@")
if [ "${DIFFPD_EDGE_CHECKS:-1}" != 0 ]; then
  ./scripts/fuzz.sh
fi

if [ "$sanitize" = auto ]; then
  # Measured on a clean clone without a compiler cache on a 2-core machine:
  # the sanitized core tier took 1.25 times the phases before it.
  so_far=$((SECONDS - start))
  projected=$((so_far * 23 / 10))
  if [ "$projected" -le $((budget_min * 60)) ]; then
    sanitize=1
  else
    echo "test.sh: the sanitized core tests are skipped: the checks so far took $((so_far / 60)) min," \
      "and with the sanitized build and run (about 1.3 times as long) the command would take about" \
      "$((projected / 60)) min, past the budget of $budget_min min (DIFFPD_TIME_BUDGET_MINUTES)." \
      "DIFFPD_SANITIZE=1 runs them regardless." >&2
    sanitize=0
  fi
fi
if [ "$sanitize" = 1 ]; then
  ./scripts/sanitize.sh
fi
