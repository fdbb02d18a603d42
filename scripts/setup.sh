#!/usr/bin/env bash
# Installs the Debian packages DiffPD needs (only those missing) and builds
# the project in Release mode into build/. Used by run.sh and test.sh.
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(g++ make cmake pkg-config libeigen3-dev libsuitesparse-dev libmetis-dev libceres-dev
          coinor-libipopt-dev libgtest-dev libgmock-dev libomp-dev libcli11-dev nlohmann-json3-dev
          gnuplot-nox tetgen clang-format git)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing missing Debian packages: ${missing[*]}" >&2
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
fi

JOBS="${DIFFPD_BUILD_JOBS:-$(nproc)}"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >&2
cmake --build build -j "$JOBS" "$@" >&2
