#!/usr/bin/env bash
# Builds the libFuzzer harnesses of fuzz/ with clang (AddressSanitizer and
# UndefinedBehaviorSanitizer on) into build-fuzz/ and runs each for a fixed
# time, starting from its seed corpus fuzz/corpus/<reader>/ (left unchanged;
# new inputs go to build-fuzz/corpus/<reader>/). A crash, a sanitizer report,
# an exception other than InvalidInputError, an input taking over 10 s or
# over 2 GiB fails the run; the input that did is saved in
# build-fuzz/artifacts/<reader>/ and printed.
#
# DIFFPD_FUZZ_SECONDS: seconds per harness (default 20). Arguments: the
# readers to run (default all: obj tetgen gmsh captured_motion starfish_recording reference_curve).
set -euo pipefail
cd "$(dirname "$0")/.."

seconds="${DIFFPD_FUZZ_SECONDS:-20}"
readers=("$@")
[ ${#readers[@]} -gt 0 ] || readers=(obj tetgen gmsh captured_motion starfish_recording reference_curve)
build=build-fuzz
clang=$(command -v clang++ || command -v clang++-14 || true)
if [ -z "$clang" ]; then
  echo "fuzz: clang++ not found (Debian packages clang and libclang-rt-14-dev; scripts/setup.sh installs them)" >&2
  exit 1
fi
launcher=()
if command -v ccache >/dev/null 2>&1; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
cmake -S fuzz -B "$build" -DCMAKE_CXX_COMPILER="$clang" "${launcher[@]}" >/dev/null
cmake --build "$build" -j "${DIFFPD_BUILD_JOBS:-$(nproc)}" >/dev/null

export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
failed=()
for reader in "${readers[@]}"; do
  mkdir -p "$build/corpus/$reader" "$build/artifacts/$reader"
  log="$build/fuzz_$reader.log"
  if "$build/fuzz_$reader" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=8192 \
      -print_final_stats=1 -artifact_prefix="$build/artifacts/$reader/" \
      "$build/corpus/$reader" "fuzz/corpus/$reader" >"$log" 2>&1; then
    echo "fuzz: $reader: $(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$') inputs in ${seconds} s, no finding"
  else
    echo "fuzz: $reader: FAILED (log $log):" >&2
    grep -E 'ERROR|runtime error|terminate|Test unit written|SUMMARY' "$log" | head -20 >&2 || tail -20 "$log" >&2
    failed+=("$reader")
  fi
done
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz: findings in ${failed[*]}" >&2
  exit 1
fi
