#!/usr/bin/env bash
# Quick start: installs what is missing, builds Release into build/, and runs
# the main job. `./run.sh` runs calibrate-cantilever (a generated mesh and the
# captured motion in data/: nothing outside the repository), writing into
# out/calibrate-cantilever/; `./run.sh PROBLEM [options]` runs
# `diffpd run PROBLEM [options]` (see `build/bin/diffpd run --help`).
set -euo pipefail
cd "$(dirname "$0")"
./scripts/setup.sh --target diffpd_cli
if [ $# -eq 0 ]; then
  exec build/bin/diffpd run calibrate-cantilever --out out/calibrate-cantilever
fi
exec build/bin/diffpd run "$@"
