#!/bin/bash
# What OpenMP's wait setting costs: pd-lbfgs's loss-and-gradient evaluation at
# the Table's x_init (routing tendon and cantilever rows, 2 threads), under
# libgomp's default spin (GOMP_SPINCOUNT=300000), the diffpd program's short
# spin (1000) and OMP_WAIT_POLICY=passive, interleaved over ROUNDS rounds of 3
# evaluations each. Prints the medians as a table, and as JSON to FILE.
#   benchmarks/openmp_waits.sh [ROUNDS=3] [FILE.json]
# Run it once on an idle machine and once beside other work: the settings
# trade a little idle speed for a lot under load.
set -euo pipefail
rounds=${1:-3}
json=${2:-}
program=${DIFFPD:-build/bin/diffpd}
raw=$(mktemp)
trap 'rm -f "$raw"' EXIT
for round in $(seq "$rounds"); do
  for setting in GOMP_SPINCOUNT=300000 GOMP_SPINCOUNT=1000 OMP_WAIT_POLICY=passive; do
    for row in routing-tendon cantilever; do
      env -u OMP_WAIT_POLICY -u GOMP_SPINCOUNT "$setting" "$program" table --rows "$row" --methods pd-lbfgs \
        --draws 0 --evaluations 3 --threads 2 2>&1 | grep " evaluation [0-9]" | sed "s/^/$setting /" >> "$raw"
    done
  done
done
/usr/bin/python3 - "$raw" "$json" "$(cat /proc/loadavg)" <<'PY'
import json, re, statistics, sys
raw, out, load = sys.argv[1], sys.argv[2], sys.argv[3]
samples = {}
for line in open(raw):
    m = re.match(r'(\S+) \[table\] (\S+) pd-lbfgs evaluation \d+/\d+: .*forward ([\d.]+) s, backward ([\d.]+) s', line)
    if m:
        samples.setdefault((m[2], m[1]), []).append((float(m[3]), float(m[4])))
rows = []
print(f"# pd-lbfgs loss + gradient at x_init, 2 threads, medians (load average at the end: {load})")
print(f"{'row':15s} {'setting':24s} {'n':>3s} {'forward s':>10s} {'backward s':>11s} {'total s':>8s}")
for (row, setting), v in sorted(samples.items()):
    f = statistics.median(x[0] for x in v)
    b = statistics.median(x[1] for x in v)
    t = statistics.median(x[0] + x[1] for x in v)
    rows.append({"row": row, "setting": setting, "samples": len(v), "forward_s": f, "backward_s": b, "total_s": t})
    print(f"{row:15s} {setting:24s} {len(v):3d} {f:10.3f} {b:11.3f} {t:8.3f}")
if out:
    json.dump({"load_average_at_end": load, "rows": rows}, open(out, "w"), indent=2)
PY
