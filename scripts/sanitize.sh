#!/usr/bin/env bash
# Builds the whole test suite with AddressSanitizer and UndefinedBehaviorSanitizer
# into build-sanitize/ (-O2 -g1, frame pointers kept) and runs it with CTest. Any
# report (out-of-bounds access, use after free, leak, signed overflow, misaligned
# or null access, invalid shift, float-to-int overflow, ...) aborts the test that
# produced it, so the run fails.
#
# Scope (DIFFPD_SANITIZE_SCOPE):
#   core (default)  the tests labelled `core`: every test of the library, the
#                   rollout core and the optimiser adapters that needs
#                   neither the problem library nor a program built on it.
#                   Only their targets are built (about half of the whole
#                   build). The file readers, under the same sanitizers, are
#                   fuzzed by scripts/fuzz.sh.
#   ci              the 32 core tests labelled `sanitize_ci` (tests/CMakeLists.txt
#                   lists them and why): the scope ./test.sh, and so CI, runs
#                   first; about 13 min on 2 cores without a compiler cache.
#   core-rest       the other core tests: what ./test.sh runs after `ci`
#                   where the time budget allows, so that ci and core-rest
#                   together are the scope core.
#   all             the whole suite, problems, Python and MPI tests included.
#
# The project's libraries are built shared here (BUILD_SHARED_LIBS): each
# test program then links a few objects instead of copying the instrumented
# library (a static libdiffpd.a of 120 MB with its line tables made each
# program 70-90 MB, and linking them took a third of the build).
#
# Not run here, with the reason:
#   format_check            checks source formatting; compiles nothing.
#   install_consumer_test   builds an outside project against the installed
#                           package with its own (unsanitized) flags, which cannot
#                           link the sanitized library.
# Extra arguments go to ctest (e.g. -R mesh_). DIFFPD_TEST_JOBS sets the job count.
set -euo pipefail
cd "$(dirname "$0")/.."

build=build-sanitize
# EIGEN_MALLOC_ALREADY_ALIGNED=1: under -fsanitize=address Eigen would switch to
# its own aligned allocator (an offset stored before each block), while the
# system's libceres, built without it, frees with plain free(); a block that
# crosses the two (shared template instances bind to either copy) is then freed
# wrongly. malloc on x86-64 returns 16-byte aligned blocks, all the project needs
# (no AVX: -march=x86-64-v2 at most), so both sides use malloc/free directly.
flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
flags="$flags -DEIGEN_MALLOC_ALREADY_ALIGNED=1"
# The Python package is built for Debian's interpreter, as scripts/setup.sh
# does. The interpreter is not sanitized: python_tests preloads the runtime so
# the extension module can load, without leak detection (the interpreter
# keeps its objects alive at exit by design), and the C++ runtime with it, or
# the runtime's exception interceptor finds no __cxa_throw and aborts at the
# first C++ exception.
asan_runtime="$(${CXX:-c++} -print-file-name=libasan.so) $(${CXX:-c++} -print-file-name=libstdc++.so)"
python=()
if [ -x /usr/bin/python3 ]; then python=(-DPython_EXECUTABLE=/usr/bin/python3); fi
launcher=()
if command -v ccache >/dev/null 2>&1; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
# Ninja where the build directory is new (an existing one keeps its
# generator): it builds the chosen test programs in parallel, where the
# Makefiles' top level builds one named target after another, one file at a
# time.
generator=()
if [ ! -f "$build/CMakeCache.txt" ] && command -v ninja >/dev/null 2>&1; then generator=(-G Ninja); fi

scope="${DIFFPD_SANITIZE_SCOPE:-core}"
case "$scope" in
  core | ci | core-rest | all) ;;
  *)
    echo "sanitize: DIFFPD_SANITIZE_SCOPE = '$scope' is invalid: must be core, ci, core-rest or all" >&2
    exit 2
    ;;
esac

# -O2: the tests run about 10 times slower than the Release build's under
# the sanitizers, against about 20 times at -O1 (Eigen's kernels need the
# inlining); -g1: line tables only, enough for file:line in every report,
# and about a quarter less compile time than full debug information. The
# test files themselves (DIFFPD_TEST_CXX_FLAGS) at -O0: the sanitizers'
# instrumentation of the GoogleTest macros makes each of them a 15-40 s
# compile at -O2 and 2-3 times less at -O0, while the tests spend their time
# in the libraries, still at -O2.
cmake -S . -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo "${launcher[@]}" \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" \
  -DCMAKE_CXX_FLAGS="$flags" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
  -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined" \
  -DBUILD_SHARED_LIBS=ON -DDIFFPD_BUILD_BENCHMARKS=OFF -DDIFFPD_TEST_CXX_FLAGS=-O0 "${python[@]}" \
  "-DDIFFPD_PYTHON_TEST_ENVIRONMENT=LD_PRELOAD=$asan_runtime;ASAN_OPTIONS=halt_on_error=1:detect_leaks=0" \
  "-DDIFFPD_MPI_TEST_ENVIRONMENT=ASAN_OPTIONS=halt_on_error=1:detect_leaks=1:fast_unwind_on_malloc=0" >/dev/null
selection=()
if [ "$scope" != all ]; then
  case "$scope" in
    core) selection=(-L '^core$') ;;
    ci) selection=(-L '^sanitize_ci$') ;;
    core-rest) selection=(-L '^core$' -LE '^sanitize_ci$') ;;
  esac
  # Every core test is an executable of the same name (diffpd_add_test).
  mapfile -t targets < <(cd "$build" && ctest -N "${selection[@]}" | sed -n 's/^ *Test *#[0-9]*: *//p')
  if [ ${#targets[@]} -eq 0 ]; then
    echo "sanitize: scope $scope selects no test" >&2
    exit 1
  fi
  echo "sanitize: scope $scope: building and running ${#targets[@]} tests" >&2
  cmake --build "$build" -j "${DIFFPD_BUILD_JOBS:-$(nproc)}" --target "${targets[@]}"
else
  cmake --build "$build" -j "${DIFFPD_BUILD_JOBS:-$(nproc)}"
fi

# halt_on_error: the first report ends the process with a failing status.
# detect_leaks: LeakSanitizer runs at exit; scripts/lsan.supp lists leaks
# inside third-party libraries that the project cannot free. The MPI test
# unwinds every allocation fully (fast_unwind_on_malloc=0, slow): OpenMPI is
# built without frame pointers, and its leaks are only recognised by their
# callers deeper in the stack.
export ASAN_OPTIONS="halt_on_error=1:detect_leaks=1"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
export LSAN_OPTIONS="suppressions=$PWD/scripts/lsan.supp:print_suppressions=0"
cd "$build"
ctest --output-on-failure -j "${DIFFPD_TEST_JOBS:-$(nproc)}" \
  -E '^(format_check|install_consumer_test)$' "${selection[@]}" "$@"
