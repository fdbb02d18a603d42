#!/usr/bin/env bash
# Installs what is missing, builds Release into build/ and runs the whole test
# suite with CTest; then every file reader's fuzz harness for a fixed time
# (scripts/fuzz.sh, in build-fuzz/; DIFFPD_EDGE_CHECKS=0 skips it); then the
# core tests (the library's, the rollout core's and the optimiser adapters')
# again under AddressSanitizer and UndefinedBehaviorSanitizer
# (scripts/sanitize.sh, in build-sanitize/), in two tiers: first the chosen
# third of them that covers every library area (scope `ci`), then the rest
# (scope `core-rest`). DIFFPD_SANITIZE_SCOPE=core or =all instead runs that
# scope in one go (all: the whole suite, a second full build).
#
# Each tier is a second build and a slow run; DIFFPD_SANITIZE chooses:
#   auto (default)  run a tier when the time so far times its factor fits
#                   within DIFFPD_TIME_BUDGET_MINUTES (default 45), and
#                   otherwise say so and skip it (and the tiers after it),
#                   so that the command ends within the budget on a slow
#                   machine. The factors, measured on a clean clone without
#                   a compiler cache on 2 cores: `ci` took 0.49 times the
#                   phases before it, `core-rest` 0.47 times the phases
#                   before it (ci included), both projected at 0.5 times,
#                   and `core` or `all` at 1.3 times;
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

case "${DIFFPD_SANITIZE_SCOPE:-}" in
  "" | core | ci | core-rest | all) ;;
  *)
    echo "test.sh: DIFFPD_SANITIZE_SCOPE = '$DIFFPD_SANITIZE_SCOPE' is invalid: must be core, ci, core-rest or all" >&2
    exit 2
    ;;
esac

start=$SECONDS
./scripts/setup.sh
(cd build && ctest --output-on-failure -j "${DIFFPD_TEST_JOBS:-$(nproc)}" "$@")
if [ "${DIFFPD_EDGE_CHECKS:-1}" != 0 ]; then
  ./scripts/fuzz.sh
fi

# Each scope's time as a percentage of the time before it (see above).
declare -A factor=([ci]=50 [core-rest]=50 [core]=130 [all]=130)

# Whether a sanitized scope fits: the time so far times (1 + its factor)
# within the budget. Says why where it does not.
fits() {
  local tier=$1 so_far projected
  so_far=$((SECONDS - start))
  projected=$((so_far * (100 + factor[$tier]) / 100))
  if [ "$projected" -le $((budget_min * 60)) ]; then
    return 0
  fi
  echo "test.sh: the sanitized tests (scope $tier) are skipped: the checks so far took $((so_far / 60)) min," \
    "and with this scope's sanitized build and run the command would take about" \
    "$((projected / 60)) min, past the budget of $budget_min min (DIFFPD_TIME_BUDGET_MINUTES)." \
    "DIFFPD_SANITIZE=1 runs them regardless." >&2
  return 1
}

# wanted <scope>: whether DIFFPD_SANITIZE asks for the scope. The scope
# itself runs outside any condition, so that its failure fails the command.
wanted() {
  [ "$sanitize" = 1 ] || { [ "$sanitize" = auto ] && fits "$1"; }
}

scope="${DIFFPD_SANITIZE_SCOPE:-}"
if [ -n "$scope" ]; then
  if wanted "$scope"; then
    DIFFPD_SANITIZE_SCOPE="$scope" ./scripts/sanitize.sh
  fi
elif wanted ci; then
  DIFFPD_SANITIZE_SCOPE=ci ./scripts/sanitize.sh
  if wanted core-rest; then
    DIFFPD_SANITIZE_SCOPE=core-rest ./scripts/sanitize.sh
  fi
fi
