#!/usr/bin/env bash
# Installs what is missing, builds Release into build/ and runs the whole test
# suite with CTest; then every file reader's fuzz harness for a fixed time
# (scripts/fuzz.sh, in build-fuzz/; DIFFPD_EDGE_CHECKS=0 skips it); then a
# chosen third of the core tests (the library's, the rollout core's and the
# optimiser adapters') again under AddressSanitizer and
# UndefinedBehaviorSanitizer (scripts/sanitize.sh's scope `ci`, in
# build-sanitize/; DIFFPD_SANITIZE_SCOPE=core runs all core tests there,
# =all the whole suite, a second full build).
#
# The sanitized tests are a second build and take about 0.45 times as long as
# everything before them (the scope `core` took 1.25 times, measured with
# Makefiles and a static library). DIFFPD_SANITIZE chooses:
#   auto (default)  run them when the time so far times 1.45 (times 2.3 for
#                   the scope core or all) fits within
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

scope="${DIFFPD_SANITIZE_SCOPE:-ci}"
if [ "$sanitize" = auto ]; then
  # Measured on a clean clone without a compiler cache on a 2-core machine:
  # the sanitized tier took 0.44 (scope ci) and 1.25 (scope core, before the
  # build used Ninja) times the phases before it.
  so_far=$((SECONDS - start))
  factor=145
  [ "$scope" = ci ] || factor=230
  projected=$((so_far * factor / 100))
  if [ "$projected" -le $((budget_min * 60)) ]; then
    sanitize=1
  else
    echo "test.sh: the sanitized tests (scope $scope) are skipped: the checks so far took $((so_far / 60)) min," \
      "and with the sanitized build and run the command would take about" \
      "$((projected / 60)) min, past the budget of $budget_min min (DIFFPD_TIME_BUDGET_MINUTES)." \
      "DIFFPD_SANITIZE=1 runs them regardless." >&2
    sanitize=0
  fi
fi
if [ "$sanitize" = 1 ]; then
  DIFFPD_SANITIZE_SCOPE="$scope" ./scripts/sanitize.sh
fi
