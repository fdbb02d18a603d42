#!/usr/bin/env bash
# The whole `diffpd stress` grid in parallel shards (one per problem, method
# and Young's modulus: 80 by default), then one summary.
#
#   scripts/stress_grid.sh [-j JOBS] [-o DIR] [-b DIFFPD] [-p PROBLEMS] [-m METHODS] [-l STEPS]
#                          [-- extra stress options]
#
# PROBLEMS: comma-separated (default cantilever,falling-cube,bouncing-ball,
# rolling-sphere); METHODS likewise (default newton-cholesky,pd,newton-pcg,
# pd-lbfgs). -l STEPS adds one shard per problem and method with the
# long cases (`diffpd stress --long-steps STEPS --long-only`: the grid's
# extreme corners for STEPS steps), run first.
# JOBS shards run at a time (default: the number of processors), each on one
# thread. DIR (default out/stress) receives one JSON list and one log per
# shard, all.json (every case) and summary.txt: case counts per outcome, the
# gradient checks with unresolved inputs or inputs decided by the tangent,
# and the smallest margin of a resolved input. Extra options (e.g. --steps
# 50) go to every shard. Needs python3 for the summary.
set -euo pipefail

jobs=$(nproc)
out=out/stress
diffpd=build/bin/diffpd
problems=cantilever,falling-cube,bouncing-ball,rolling-sphere
methods=newton-cholesky,pd,newton-pcg,pd-lbfgs
long_steps=0
while [[ $# -gt 0 ]]; do
  case "$1" in
    -j) jobs="$2"; shift 2 ;;
    -p) problems="$2"; shift 2 ;;
    -m) methods="$2"; shift 2 ;;
    -l) long_steps="$2"; shift 2 ;;
    -o) out="$2"; shift 2 ;;
    -b) diffpd="$2"; shift 2 ;;
    --) shift; break ;;
    *) echo "stress_grid.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
extra=("$@")
mkdir -p "$out"

shards=()
IFS=, read -r -a problem_list <<<"$problems"
IFS=, read -r -a method_list <<<"$methods"
if [[ "$long_steps" -gt 0 ]]; then
  for problem in "${problem_list[@]}"; do
    for method in "${method_list[@]}"; do shards+=("$problem $method long"); done
  done
fi
for problem in "${problem_list[@]}"; do
  for method in "${method_list[@]}"; do
    for e in 1e10 1e8 1e6 1e4 1e2; do shards+=("$problem $method $e"); done
  done
done

run_shard() {
  local problem=$1 method=$2 e=$3
  local name="$out/${problem}_${method}_E${e}"
  local grid=(--E "$e")
  [[ "$e" == long ]] && grid=(--long-steps "$long_steps" --long-only)
  "$diffpd" stress --problems "$problem" --methods "$method" "${grid[@]}" --threads 1 --json "${extra[@]}" \
    >"$name.json" 2>"$name.log" || [[ $? -eq 4 ]]  # 4: violations, reported in the summary
}
export -f run_shard
export out diffpd long_steps
export extra_joined="${extra[*]:-}"

printf '%s\n' "${shards[@]}" |
  xargs -P "$jobs" -I{} bash -c 'extra=(${extra_joined}); run_shard {}'

python3 - "$out" <<'EOF'
import glob, json, math, sys
out = sys.argv[1]
cases = []
for f in sorted(glob.glob(out + "/*_E*.json")):
    with open(f) as h:
        text = h.read().strip()
    if not text:
        print("incomplete shard:", f)
        continue
    cases += json.loads(text)
with open(out + "/all.json", "w") as h:
    json.dump(cases, h, indent=1)
count = lambda o: sum(c["outcome"] == o for c in cases)
checks = [c for c in cases if c["gradcheck_run"]]
unresolved = [c for c in checks if c["gradcheck_unresolved"]]
tangent = [c for c in checks if c.get("gradcheck_tangent")]
margins = [c["gradcheck_margin"] for c in checks if c["gradcheck_margin"] is not None]
lines = [
    f"{len(cases)} cases: {count('ok')} ok, {count('failed')} failed with a solver error, {count('violation')} violations"
    f" ({sum(c.get('long_case', False) for c in cases)} long, {sum(c.get('contact_steps', 0) > 0 for c in cases)}"
    f" with contact)",
    f"gradient checks: {len(checks)} run, {len(unresolved)} with unresolved inputs, "
    f"{len(tangent)} with inputs decided by the tangent, smallest margin of a resolved input "
    f"{min(margins) if margins else math.inf:.3g}",
]
for c in unresolved:
    lines.append(f"unresolved: {c['problem']} {c['method']} E={c['youngs_modulus']:g} nu={c['poissons_ratio']:g} "
                 f"h={c['time_step']:g}: {' '.join(c['gradcheck_unresolved'])}")
for c in cases:
    if c["outcome"] == "violation":
        lines.append(f"violation: {c['problem']} {c['method']} E={c['youngs_modulus']:g} nu={c['poissons_ratio']:g} "
                     f"h={c['time_step']:g}: {c['message']}")
for c in sorted(checks, key=lambda c: c["gradcheck_margin"] if c["gradcheck_margin"] is not None else math.inf)[:5]:
    lines.append(f"margin {c['gradcheck_margin']:.3g}: {c['problem']} {c['method']} E={c['youngs_modulus']:g} "
                 f"nu={c['poissons_ratio']:g} h={c['time_step']:g}")
with open(out + "/summary.txt", "w") as h:
    h.write("\n".join(lines) + "\n")
print("\n".join(lines))
EOF
