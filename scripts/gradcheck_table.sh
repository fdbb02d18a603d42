#!/usr/bin/env bash
# `diffpd gradcheck` for every problem and method: one JSON document with
# every result and a markdown table (verdict, smallest margin, and per input
# kind error / floor / basis), e.g. into docs/results/.
#
#   scripts/gradcheck_table.sh [-p "problem ..."] [-m "method ..."] [-s STEPS] [-t SECONDS]
#                              [-c CONCURRENT] [-a "extra gradcheck options"] [-o PREFIX] [-b DIFFPD]
#
# Defaults: every problem `diffpd list` names, the methods newton-cholesky,
# newton-ldlt, newton-pcg, pd, pd-lbfgs and semi-implicit, 3 steps, at most
# 600 s per run (a run stopped by it is listed as "timeout"), PREFIX
# out/gradcheck_table (writes PREFIX.json and PREFIX.md), one thread per run
# at the solve tolerance the tool recommends, CONCURRENT (default 1)
# perturbed rollouts at once (`--concurrent-rollouts`); -a adds options to
# every run (e.g. "--dt 1e-4" for semi-implicit, which diverges at most
# problems' own time step). Needs python3.
set -euo pipefail

diffpd=build/bin/diffpd
problems=""
methods="newton-cholesky newton-ldlt newton-pcg pd pd-lbfgs semi-implicit"
steps=3
limit=600
prefix=out/gradcheck_table
concurrent=1
extra=""
while [[ $# -gt 0 ]]; do
  case "$1" in
    -p) problems="$2"; shift 2 ;;
    -m) methods="$2"; shift 2 ;;
    -s) steps="$2"; shift 2 ;;
    -t) limit="$2"; shift 2 ;;
    -c) concurrent="$2"; shift 2 ;;
    -a) extra="$2"; shift 2 ;;
    -o) prefix="$2"; shift 2 ;;
    -b) diffpd="$2"; shift 2 ;;
    *) echo "gradcheck_table.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
[[ -n "$problems" ]] || problems=$("$diffpd" list | awk '{print $1}')
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$(dirname "$prefix")"

for problem in $problems; do
  for method in $methods; do
    start=$(date +%s.%N)
    status=0
    timeout "$limit" "$diffpd" gradcheck "$problem" --method "$method" --steps "$steps" --threads 1 \
      --concurrent-rollouts "$concurrent" $extra --json \
      >"$work/$problem.$method.json" 2>"$work/$problem.$method.log" || status=$?
    end=$(date +%s.%N)
    echo "$problem $method $status $(awk "BEGIN { print $end - $start }")" >>"$work/runs.txt"
    echo "gradcheck $problem --method $method: exit $status" >&2
  done
done

python3 - "$work" "$prefix" "$steps" <<'EOF'
import json, sys
work, prefix, steps = sys.argv[1], sys.argv[2], sys.argv[3]
rows = []
for line in open(work + "/runs.txt"):
    problem, method, status, seconds = line.split()
    row = {"problem": problem, "method": method, "exit_status": int(status), "seconds": float(seconds)}
    text = open(f"{work}/{problem}.{method}.json").read().strip()
    if status == "124":
        row["outcome"] = "timeout"
    elif text:
        row["outcome"] = "checked"
        row["result"] = json.loads(text)
    else:
        row["outcome"] = "error"
        row["message"] = open(f"{work}/{problem}.{method}.log").read().strip().splitlines()[-1:]
    rows.append(row)
with open(prefix + ".json", "w") as h:
    json.dump({"steps": int(steps), "runs": rows}, h, indent=1)
EOF
python3 "$(dirname "$0")/gradcheck_table_report.py" "$prefix.json" | tee "$prefix.md"
