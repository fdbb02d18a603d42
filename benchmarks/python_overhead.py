#!/usr/bin/env python3
"""Benchmark (not a test): the Python package's overhead on a rollout.

Times the same rollout (a registered problem's default one, the cantilever by
default) through the C++ API (the rollout_timing program) and through diffpd
from Python (Simulator.simulate, and the torch Function diffpd.torch.rollout
with its conversions), in alternating rounds so that both see the same
machine load, and prints a table and, with --json, one JSON object:
median seconds of each and the overhead (python / C++ - 1). As wall times on a
loaded machine vary by several percent between runs, each run also records
the time its steps took as the simulator measures them (Rollout's
forward_seconds, BackwardReport.seconds); wall minus that is the cost around
the steps (the call, the conversions), and its median excess over the C++
caller's, relative to the C++ wall time, is the paired overhead reported.

Usage: PYTHONPATH=build/python python3 benchmarks/python_overhead.py
           [--problem cantilever] [--rtol 1e-4] [--rounds 3] [--repeat 3] [--method pd-lbfgs] [--backward] [--json]
       (--bin: the directory of rollout_timing, default build/bin)
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import time

import numpy as np

import diffpd


def python_times(problem, method, rtol, repeat, backward, use_torch):
    options = diffpd.SolverOptions(method=diffpd.parse_method(method), time_step=problem.default_time_step,
                                   rel_tolerance=rtol)
    sim = diffpd.Simulator(problem.make_scene(), options)
    initial = problem.initial_state(sim)
    steps = problem.default_steps
    inputs = problem.inputs(sim, steps)
    dx = np.zeros((steps + 1, sim.num_dofs))
    dx[-1] = 1.0
    loss = diffpd.LossGradient(dx)
    if use_torch:
        import torch
        import diffpd.torch as dtorch
        # The torch variant drives no inputs (the cantilever's default rollout has none).
        x0 = torch.from_numpy(initial.x.copy()).requires_grad_()  # so that the rollout keeps its ctx
        v0 = torch.from_numpy(initial.v.copy())

        def run():
            t0 = time.perf_counter()
            positions, _ = dtorch.rollout(sim, x0, v0, steps=steps)
            forward = time.perf_counter() - t0
            function = positions.grad_fn
            inner = function.rollout.forward_seconds()
            if not backward:
                return forward, None, inner, None
            # The reverse pass's own time: a second reverse pass of the same
            # rollout through the simulator (the Function keeps no report).
            t1 = time.perf_counter()
            positions[-1].sum().backward()
            elapsed = time.perf_counter() - t1
            return forward, elapsed, inner, sim.backward(function.rollout, loss).report.seconds
    else:
        def run():
            t0 = time.perf_counter()
            rollout = sim.simulate(initial, inputs)
            forward = time.perf_counter() - t0
            if not backward:
                return forward, None, rollout.forward_seconds(), None
            t1 = time.perf_counter()
            gradient = sim.backward(rollout, loss)
            return forward, time.perf_counter() - t1, rollout.forward_seconds(), gradient.report.seconds
    run()  # the PD factorisation, as rollout_timing's untimed rollout
    return [run() for _ in range(repeat)]


def cpp_times(binary, name, method, rtol, repeat, backward):
    command = [binary, name, "--method", method, "--rtol", repr(rtol), "--repeat", str(repeat)]
    command += ["--backward"] if backward else []
    out = json.loads(subprocess.run(command, check=True, capture_output=True, text=True).stdout)
    backward_times = out.get("backward_seconds", [None] * repeat)
    backward_inner = out.get("backward_inner_seconds", [None] * repeat)
    return list(zip(out["forward_seconds"], backward_times, out["forward_inner_seconds"], backward_inner))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--problem", default="cantilever")
    parser.add_argument("--method", default="pd-lbfgs", help="`diffpd run`'s default")
    parser.add_argument("--rtol", type=float, default=1e-4, help="step tolerance (`diffpd run`'s default)")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--backward", action="store_true")
    parser.add_argument("--no-torch", action="store_true")
    parser.add_argument("--bin", default=os.path.join(os.path.dirname(__file__), "..", "build", "bin"))
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()

    problem = diffpd.problems.make(args.problem)
    binary = os.path.join(args.bin, "rollout_timing")
    kinds = ["cpp", "python"] + ([] if args.no_torch else ["torch"])
    times = {kind: [] for kind in kinds}
    for _ in range(args.rounds):
        times["cpp"] += cpp_times(binary, args.problem, args.method, args.rtol, args.repeat, args.backward)
        times["python"] += python_times(problem, args.method, args.rtol, args.repeat, args.backward, False)
        if "torch" in times:
            times["torch"] += python_times(problem, args.method, args.rtol, args.repeat, args.backward, True)

    result = {"problem": args.problem, "method": args.method, "steps": problem.default_steps,
              "runs": args.rounds * args.repeat}
    for kind in kinds:
        result[kind + "_forward_median"] = statistics.median(t[0] for t in times[kind])
        if args.backward:
            result[kind + "_backward_median"] = statistics.median(t[1] for t in times[kind])
    passes = [("forward", 0, 2)] + ([("backward", 1, 3)] if args.backward else [])
    for kind in kinds:
        for name, wall, inner in passes:
            result[f"{kind}_{name}_around_steps_median"] = statistics.median(t[wall] - t[inner] for t in times[kind])
    for kind in kinds[1:]:
        for name, wall, inner in passes:
            result[f"{kind}_{name}_overhead"] = (result[f"{kind}_{name}_median"] / result[f"cpp_{name}_median"] - 1)
            result[f"{kind}_{name}_paired_overhead"] = (
                (result[f"{kind}_{name}_around_steps_median"] - result[f"cpp_{name}_around_steps_median"]) /
                result[f"cpp_{name}_median"])
    out = sys.stderr if args.json else sys.stdout
    print(f"# {args.problem}, {args.method}, {problem.default_steps} steps, median of {result['runs']} runs each",
          file=out)
    header = f"{'caller':8}"
    for name, _, _ in passes:
        header += f" {name + '_s':>11} {'wall/C++-1':>10} {'around_s':>9} {'paired':>8}"
    print(header, file=out)
    for kind in kinds:
        row = f"{kind:8}"
        for name, _, _ in passes:
            row += (f" {result[f'{kind}_{name}_median']:11.4f} {100 * result.get(f'{kind}_{name}_overhead', 0):9.2f}%"
                    f" {result[f'{kind}_{name}_around_steps_median']:9.5f}"
                    f" {100 * result.get(f'{kind}_{name}_paired_overhead', 0):7.3f}%")
        print(row, file=out)
    if args.json:
        print(json.dumps(result))


if __name__ == "__main__":
    main()
