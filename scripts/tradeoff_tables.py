#!/usr/bin/env python3
"""Markdown tables from the reports of `diffpd tradeoff` (<problem>.json).

    scripts/tradeoff_tables.py readme FRONTS_DIR [DEFAULTS_DIR]
    scripts/tradeoff_tables.py fronts FRONTS_DIR
    scripts/tradeoff_tables.py defaults DEFAULTS_DIR

readme: one row per problem of FRONTS_DIR (the fronts of every method, e.g.
docs/results/tradeoff): the default (method, rel_tolerance), its gradient
error, and for gradient-error bounds 1e-3, 1e-2 and 1e-1 the loosest swept
rel_tolerance of the default method at which it and every tighter one stay
below the bound, with its factor over the default ("x100": a hundred times
looser; "/100": must be a hundred times tighter), PD-LBFGS's seconds at its
loosest tolerance below 1e-3 against the fastest Newton run below it; with
DEFAULTS_DIR, the default's slowdown over the front measured there.

fronts: one row per problem of FRONTS_DIR with its size, the default's
seconds, error and slowdown, the loosest tolerances per bound, the fastest
run below 1e-3, PD-LBFGS against Newton there, and the counts of
monotonicity violations and failed runs.

defaults: one row per problem of DEFAULTS_DIR (reports of
`diffpd tradeoff --clock cpu --repeats N`): the default's seconds (the
fastest run with its settings), its gradient error, the fastest run at least
as accurate and the slowdown.
"""
import glob
import json
import os
import sys


def reports(directory):
    out = {}
    for path in sorted(glob.glob(os.path.join(directory, "*.json"))):
        with open(path) as f:
            report = json.load(f)
        if isinstance(report, dict) and "default" in report and "rows" in report:
            out[report["problem"]] = report
    return out


def fmt(x):
    return "%.0e" % x if x else "-"


def factor(loosest, default):
    if not loosest:
        return "none swept"
    ratio = loosest / default
    if abs(ratio - 1) < 1e-9:
        return "%s (the default)" % fmt(loosest)
    if ratio > 1:
        return "%s (x%.0f)" % (fmt(loosest), ratio)
    return "%s (/%.0f)" % (fmt(loosest), 1 / ratio)


def loosest_of_default_method(report, bound):
    """The loosest tolerance of the default method's sweep (with the default
    run itself where its tolerance was not swept) at which it and every
    tighter run stay below `bound` (0: none): tradeoff_front.h's rule."""
    d = report["default"]
    rows = [r for r in report["rows"] if r["sweep"] == "tolerance" and r["method"] == d["method"]]
    if not any(r["value"] == d["rel_tolerance"] for r in rows):
        rows.append(report["rows"][0])
    loosest = 0
    for r in sorted(rows, key=lambda r: r["value"]):
        if r["status"] != "ok" or r["grad_rel_error"] > bound:
            break
        loosest = r["value"]
    return loosest


def slowdown(report):
    d = report["default"]
    return d.get("slowdown_over_front", 0)


def readme(fronts, defaults):
    print("| problem | default | gradient error at the default | loosest rel_tolerance for 1e-3 | for 1e-2 | "
          "for 1e-1 | pd-lbfgs over the best Newton at 1e-3 |" + (" default over its front |" if defaults else ""))
    print("|---|---|---|---|---|---|---|" + ("---|" if defaults else ""))
    for name, r in fronts.items():
        d = r["default"]
        cells = [name, "%s %s" % (d["method"], fmt(d["rel_tolerance"])), "%.1e" % d["grad_rel_error"]]
        for b in r["bounds"]:
            cells.append(factor(loosest_of_default_method(r, b["grad_rel_error_bound"]), d["rel_tolerance"]))
        b3 = r["bounds"][0]
        cells.append("%.1fx" % (b3["best_newton_seconds"] / b3["pd_lbfgs_seconds"])
                     if b3["best_newton_seconds"] and b3["pd_lbfgs_seconds"] else "-")
        if defaults:
            cells.append("%.2fx" % slowdown(defaults[name]) if name in defaults else "not measured")
        print("| " + " | ".join(cells) + " |")


def describe(row):
    what = row["sweep"]
    if row["setting"]:
        what += " " + row["setting"]
    elif row["sweep"] in ("backward_tolerance", "screening"):
        what += " %g" % row["value"]
    return "%s %s at %s" % (row["method"], what, fmt(row["rel_tolerance"]))


def defaults_table(defaults):
    print("| problem | default | repeats | seconds (CPU) | gradient error | fastest run as accurate | its seconds | "
          "its gradient error | slowdown |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name, r in defaults.items():
        d = r["default"]
        seconds = d.get("seconds_fastest_at_its_settings", d["seconds"])
        best = None
        for row in r["rows"]:
            if row["status"] != "ok" or row["sweep"] in ("time_step", "resolution"):
                continue
            if row["grad_rel_error"] <= d["grad_rel_error"] and (best is None or row["seconds"] < best["seconds"]):
                best = row
        print("| %s | %s %s | %d | %.3g | %.1e | %s | %.3g | %.1e | %.2f |" %
              (name, d["method"], fmt(d["rel_tolerance"]), r.get("repeats", 1), seconds, d["grad_rel_error"],
               "the default's settings" if best.get("default_settings") else describe(best), best["seconds"],
               best["grad_rel_error"], slowdown(r)))


def num(x):
    return "%.2g" % x


def tolerance(x):
    """A swept tolerance, or "none" where no swept tolerance met the bound (0)."""
    return "%g" % x if x else "none"


def fronts_table(fronts):
    print("| problem | DoFs | steps | variables | default | s | grad err | slowdown | loosest rtol for 1e-3 / 1e-2 / "
          "1e-1 | fastest below 1e-3 | pd-lbfgs rtol | pd-lbfgs s / best Newton s | non-monotone | failed runs |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for name, r in fronts.items():
        d = r["default"]
        rows = r["rows"]
        variables = r["variables"].rsplit("(", 1)[-1].rstrip(")")
        b3 = r["bounds"][0]
        failed = sum(1 for row in rows if row["status"] != "ok")
        met = b3["fastest_method"] != ""
        print("| %s | %d | %d | %s | %s %g | %s | %.2g | %.2f | %s | %s | %s | %s / %s | %d | %d/%d |" %
              (name, r["dofs"], r["steps"], variables, d["method"], d["rel_tolerance"], num(d["seconds"]),
               d["grad_rel_error"], d["slowdown_over_front"],
               " / ".join(tolerance(b["default_method_loosest_tolerance"]) for b in r["bounds"]),
               "%s %g" % (b3["fastest_method"], b3["fastest_rel_tolerance"]) if met else "none",
               tolerance(b3["pd_lbfgs_loosest_tolerance"]), num(b3["pd_lbfgs_seconds"]) if met else "-",
               num(b3["best_newton_seconds"]) if met and b3["best_newton_seconds"] else "none",
               len(r["monotonicity_violations"]), failed, len(rows)))


def main(argv):
    if len(argv) >= 3 and argv[1] == "readme":
        readme(reports(argv[2]), reports(argv[3]) if len(argv) > 3 else None)
    elif len(argv) == 3 and argv[1] == "fronts":
        fronts_table(reports(argv[2]))
    elif len(argv) == 3 and argv[1] == "defaults":
        defaults_table(reports(argv[2]))
    else:
        sys.stderr.write(__doc__)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
