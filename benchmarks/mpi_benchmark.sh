#!/usr/bin/env bash
# The plant calibration over several recordings (diffpd-mpi calibrate-plant)
# on 1 and 2 MPI ranks, one thread per rank: the fit's wall time (set-up
# excluded), medians of several runs, and the speed-up of 2 ranks over 1.
# Runs alternate between the rank counts so that a change in the machine's
# load affects both. Prints a table, or JSON with --json.
#
#   benchmarks/mpi_benchmark.sh [--build DIR] [--recordings N] [--runs K] [--max-iterations I] [--json]
set -euo pipefail
build=build recordings=4 runs=3 iterations=25 json=0
while [ $# -gt 0 ]; do
  case "$1" in
    --build) build=$2; shift 2 ;;
    --recordings) recordings=$2; shift 2 ;;
    --runs) runs=$2; shift 2 ;;
    --max-iterations) iterations=$2; shift 2 ;;
    --json) json=1; shift ;;
    *) echo "mpi_benchmark.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
done
program="$build/bin/diffpd-mpi"
[ -x "$program" ] || { echo "mpi_benchmark.sh: '$program' not found (build the target diffpd_mpi_cli)" >&2; exit 2; }
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_plm=isolated OMP_NUM_THREADS=1

field() { sed -n "s/^ *\"$1\": \([^,]*\),\{0,1\}$/\1/p"; }
median() { sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2}'; }

declare -A times evaluations
for ((k = 1; k <= runs; ++k)); do
  for ranks in 1 2; do
    out=$(mpiexec -n "$ranks" --oversubscribe "$program" calibrate-plant --recordings "$recordings" --threads 1 \
          --max-iterations "$iterations" --json 2>/dev/null)
    times[$ranks]+="$(echo "$out" | field fit_seconds) "
    evaluations[$ranks]=$(echo "$out" | field evaluations)
    echo "mpi_benchmark: run $k, $ranks rank(s): $(echo "$out" | field fit_seconds) s" >&2
  done
done
t1=$(echo "${times[1]}" | tr ' ' '\n' | grep . | median)
t2=$(echo "${times[2]}" | tr ' ' '\n' | grep . | median)
speedup=$(awk -v a="$t1" -v b="$t2" 'BEGIN {printf "%.3f", a / b}')
if [ "$json" -eq 1 ]; then
  printf '{"problem": "calibrate-plant", "recordings": %s, "runs": %s, "threads_per_rank": 1,\n' "$recordings" "$runs"
  printf ' "fit_seconds_1_rank": %s, "fit_seconds_2_ranks": %s, "evaluations": %s, "speedup": %s,\n' \
         "$t1" "$t2" "${evaluations[1]}" "$speedup"
  printf ' "runs_1_rank": [%s], "runs_2_ranks": [%s]}\n' "$(echo ${times[1]} | tr ' ' ',')" \
         "$(echo ${times[2]} | tr ' ' ',')"
else
  printf '%-6s %-12s %-12s\n' ranks "fit s (med)" evaluations
  printf '%-6s %-12s %-12s\n' 1 "$t1" "${evaluations[1]}" 2 "$t2" "${evaluations[2]}"
  echo "speed-up of 2 ranks over 1: $speedup (medians of $runs runs, $recordings recordings, 1 thread per rank)"
fi
