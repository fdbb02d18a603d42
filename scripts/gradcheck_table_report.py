#!/usr/bin/env python3
"""One markdown table from the JSON of `scripts/gradcheck_table.sh` runs.

    scripts/gradcheck_table_report.py RUNS.json [RUNS.json ...] > TABLE.md

A row per problem and method in the order given: the verdict, the smallest
margin and per input kind "verdict error / floor" (or "tangent ERROR (floor
FLOOR)" where the forward-mode tangent decided; "(k/n by tangent)" where it
decided k of the n directions, the error and floor being the others'), the
run's seconds; a semi-implicit run above its stability limit says "unstable", one at a step other than the
problem's says which, a run at a looser tolerance than
requested (the method did not reach it) says which; runs stopped by their time limit say "timeout", runs that ended
with an error give its last line. An error or floor the differences could not measure (every
perturbed rollout left the contact piece) reads "inf".
"""
import json
import sys


def number(x):
    return "inf" if x is None else f"{x:.1e}"


def cell(e):
    if e["verdict"] == "pass" and e.get("basis") == "tangent":
        return f"tangent {number(e['tangent_error'])} (floor {number(e['floor'])})"
    by_tangent = e.get("tangent_directions", 0)
    mixed = f" ({by_tangent}/{e['directions']} by tangent)" if 0 < by_tangent < e["directions"] else ""
    extrapolated = e.get("extrapolated_directions", 0)
    if extrapolated > 0:
        mixed += f" ({extrapolated}/{e['directions']} extrapolated)"
    return f"{e['verdict']} {number(e['error'])} / {number(e['floor'])}{mixed}"


def table(rows):
    kinds = []
    for r in rows:
        for k in r.get("result", {}).get("inputs", {}):
            if k not in kinds:
                kinds.append(k)
    lines = [f"| problem | method | verdict | smallest margin | {' | '.join(kinds)} | s |",
             "|" + "---|" * (len(kinds) + 5)]
    for r in rows:
        if r["outcome"] != "checked":
            what = r["outcome"] + ("" if r["outcome"] == "timeout" else ": " + " ".join(r.get("message", [])))
            lines.append(f"| {r['problem']} | {r['method']} | {what} | | " + " | " * len(kinds) +
                         f"{r['seconds']:.0f} |")
            continue
        res = r["result"]
        margin = res["min_margin"]
        verdict = res["verdict"]
        limit, h = res.get("explicit_stable_time_step"), res.get("time_step")
        if limit is not None and h is not None and h > limit:
            verdict += f" (unstable: h {h / limit:.2g}x its stability limit)"
        problem_h = res.get("problem_time_step")
        if problem_h is not None and h is not None and h != problem_h:
            verdict += f" (at h = {h:g} s: the problem's {problem_h:g} s is above half its stability limit)"
        requested, used = res.get("requested_rel_tolerance"), res.get("rel_tolerance")
        if requested is not None and used is not None and used != requested:
            verdict += f" (at rtol {used:g}: {requested:g} not reached)"
        cells = [cell(res["inputs"][k]) if k in res["inputs"] else "" for k in kinds]
        lines.append(f"| {r['problem']} | {r['method']} | {verdict} | "
                     f"{'inf' if margin is None else format(margin, '.3g')} | {' | '.join(cells)} | "
                     f"{r['seconds']:.0f} |")
    return "\n".join(lines) + "\n"


def main(paths):
    rows = []
    for path in paths:
        with open(path) as f:
            rows += json.load(f)["runs"]
    sys.stdout.write(table(rows))


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit("usage: gradcheck_table_report.py RUNS.json [RUNS.json ...]")
    main(sys.argv[1:])
