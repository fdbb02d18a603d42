#!/usr/bin/env bash
# Installs the Debian packages DiffPD needs (only those missing) and builds
# the project in Release mode into build/. Used by run.sh and test.sh; extra
# arguments go to `cmake --build` (e.g. --target diffpd_cli).
#
# Installing needs root: run as root, or as a user with sudo. apt's and
# dpkg's own output goes to a log file; the terminal gets what is installed,
# the download size and a progress line.
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(g++ make cmake ninja-build pkg-config libeigen3-dev libsuitesparse-dev libmetis-dev libceres-dev
          coinor-libipopt-dev libgtest-dev libgmock-dev libomp-dev libcli11-dev nlohmann-json3-dev
          gnuplot-nox tetgen clang-format git libopenmpi-dev openmpi-bin clang libclang-rt-14-dev python3-dev
          pybind11-dev python3-numpy python3-scipy python3-pytest python3-torch)

say() { echo "setup: $*" >&2; }

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

# Reads apt's status lines (APT::Status-Fd) and shows one progress line:
# rewritten in place on a terminal, every 10% otherwise.
show_progress() {
  local kind pct phase last_phase="" last_decile=-1 tty=0
  [ -t 2 ] && tty=1
  while IFS=: read -r kind _ pct _; do
    case "$kind" in
      dlstatus) phase="downloading" ;;
      pmstatus) phase="unpacking and configuring" ;;
      *) continue ;;
    esac
    pct=${pct%%.*}
    if [ "$phase" != "$last_phase" ]; then
      [ $tty -eq 1 ] && [ -n "$last_phase" ] && printf '\n' >&2
      last_phase=$phase
      last_decile=-1
    fi
    if [ $tty -eq 1 ]; then
      printf '\rsetup: %s %3d%%' "$phase" "$pct" >&2
    elif [ $((pct / 10)) -gt $last_decile ]; then
      last_decile=$((pct / 10))
      say "$phase $pct%"
    fi
  done
  [ $tty -eq 1 ] && [ -n "$last_phase" ] && printf '\n' >&2
  return 0
}

if [ ${#missing[@]} -gt 0 ]; then
  SUDO=()
  if [ "$(id -u)" -ne 0 ]; then
    if command -v sudo >/dev/null 2>&1; then
      SUDO=(sudo)
    else
      say "these Debian packages are missing: ${missing[*]}"
      say "installing them needs root, and this user is not root and has no sudo. As root, run:"
      echo "  apt-get update && apt-get install -y --no-install-recommends ${missing[*]}" >&2
      say "then run this command again (or run it as root, which installs them itself)."
      exit 1
    fi
  fi
  export DEBIAN_FRONTEND=noninteractive LC_ALL=C
  log=$(mktemp "${TMPDIR:-/tmp}/diffpd-setup.XXXXXX.log")
  say "${#missing[@]} Debian packages are missing: ${missing[*]}"
  say "updating the package lists (apt-get update; its output goes to $log)"
  if ! "${SUDO[@]}" apt-get update -q >>"$log" 2>&1; then
    tail -n 20 "$log" >&2
    say "apt-get update failed (full output: $log)"
    exit 1
  fi
  # What the installation takes (nothing is installed here): the packages
  # with their dependencies, and the bytes to download (cached files excluded).
  count=$("${SUDO[@]}" apt-get install -s --no-install-recommends "${missing[@]}" 2>>"$log" | grep -c '^Inst ' || true)
  size=$("${SUDO[@]}" apt-get install --print-uris -qq --no-install-recommends "${missing[@]}" 2>>"$log" |
         awk '{ sum += $3 } END { printf "%.1f MB", sum / 1e6 }')
  say "installing them with their dependencies: $count packages, $size to download;" \
      "this can take a few minutes"
  # apt's status lines go to the progress line (fd 3), its and dpkg's output to the log.
  if ! "${SUDO[@]}" apt-get install -y -q --no-install-recommends -o APT::Status-Fd=3 -o Dpkg::Use-Pty=0 \
      "${missing[@]}" 3>&1 1>>"$log" 2>&1 | show_progress; then
    tail -n 20 "$log" >&2
    say "apt-get install failed (full output: $log)"
    exit 1
  fi
  say "installed (apt's log: $log)"
else
  say "the ${#PACKAGES[@]} Debian packages DiffPD needs are installed"
fi

JOBS="${DIFFPD_BUILD_JOBS:-$(nproc)}"
say "building (Release) into build/ with $JOBS jobs"
# The Python package is built for Debian's interpreter, the one the packages
# above (NumPy, pytest, PyTorch) belong to, whatever python3 comes first on PATH.
# Ninja for a new build directory (an existing one keeps its generator): it
# schedules every target's files over the jobs, where the Makefiles wait for
# each library before compiling what uses it.
generator=()
if [ ! -f build/CMakeCache.txt ]; then generator=(-G Ninja); fi
# The test files themselves at -O1 (DIFFPD_TEST_CXX_FLAGS; the libraries they
# test stay at -O3), against one precompiled header (tests/CMakeLists.txt):
# together they compile in 0.58 times the time of -O3 without it. Without FMA
# (-march=x86-64-v2) and without fast-math, -O1 and -O3 round alike.
cmake -S . -B build "${generator[@]}" -DCMAKE_BUILD_TYPE=Release -DPython_EXECUTABLE=/usr/bin/python3 \
  -DDIFFPD_TEST_CXX_FLAGS=-O1 >&2
cmake --build build -j "$JOBS" "$@" >&2
