#!/usr/bin/env python3
"""Calibrating the plant (calibrate-plant, DiffPD Sec. 7.1) from Python.

Recovers Young's modulus and Poisson's ratio of the potted plant from its
captured marker motion (data/plant_motion.csv) with SciPy's L-BFGS-B: every
evaluation is one rollout (Simulator.simulate) and one reverse pass
(Simulator.backward) of L = 1/2 |r|^2, r the weighted marker residuals
(MarkerObservations), in the variables (log E, nu), nu bounded to
[0.01, 0.49] as the C++ fit. With --compare it also runs the C++ fit
(`diffpd run calibrate-plant`, Ceres' Levenberg-Marquardt) with the same
method and prints both.

Usage: PYTHONPATH=build/python python3 python/examples/calibrate_plant.py [--method pd-lbfgs] [--compare]
"""

import argparse
import json
import os
import subprocess
import time

import numpy as np
import scipy.optimize
import scipy.sparse

import diffpd


def observation_matrix(observations, steps, dofs):
    """O with r = w .* (O X - c), X the stacked positions x_0..x_K."""
    rows, cols, values = [], [], []
    for s in range(observations.num_samples):
        for step, node, weight in observations.terms(s):
            for d in range(3):
                rows.append(3 * s + d)
                cols.append(step * dofs + 3 * node + d)
                values.append(weight)
    return scipy.sparse.csr_matrix((values, (rows, cols)), shape=(3 * observations.num_samples, (steps + 1) * dofs))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--method", default="pd-lbfgs")
    parser.add_argument("--compare", action="store_true", help="also run the C++ fit (build/bin/diffpd)")
    parser.add_argument("--bin", default=os.path.join(os.path.dirname(__file__), "..", "..", "build", "bin"))
    args = parser.parse_args()

    problem = diffpd.problems.make("calibrate-plant")
    method = diffpd.parse_method(args.method)
    options = problem.fit_options(method)
    scene = problem.make_scene()
    guess, truth = problem.initial_guess(), problem.truth()
    scene.material = guess
    sim = diffpd.Simulator(scene, options)
    initial = problem.initial_state(sim)
    steps = problem.default_steps
    motion = diffpd.read_captured_motion(problem.data_path())
    observations = diffpd.MarkerObservations(motion, scene.mesh, options.time_step, steps)
    O = observation_matrix(observations, steps, sim.num_dofs)
    weights = np.concatenate([observations.weight(s) for s in range(observations.num_samples)])
    evaluations = 0

    def loss_and_gradient(p):
        nonlocal evaluations
        evaluations += 1
        youngs_modulus, poissons_ratio = float(np.exp(p[0])), float(p[1])
        sim.set_material(diffpd.MaterialParameters(youngs_modulus, poissons_ratio, guess.density))
        rollout = sim.simulate(initial, steps)
        r = observations.residuals(rollout.states)
        dx = (O.T @ (weights * r)).reshape(steps + 1, sim.num_dofs)
        gradient = sim.backward(rollout, diffpd.LossGradient(dx))
        return 0.5 * float(r @ r), np.array([gradient.youngs_modulus * youngs_modulus, gradient.poissons_ratio])

    start = time.perf_counter()
    fit = scipy.optimize.minimize(loss_and_gradient, np.array([np.log(guess.youngs_modulus), guess.poissons_ratio]),
                                  jac=True, method="L-BFGS-B", bounds=[(None, None), (0.01, 0.49)],
                                  options={"maxiter": problem.max_fit_iterations(), "ftol": 1e-12, "gtol": 1e-10})
    seconds = time.perf_counter() - start
    youngs_modulus, poissons_ratio = float(np.exp(fit.x[0])), float(fit.x[1])
    print(f"python + scipy L-BFGS-B ({args.method}): E = {youngs_modulus:.6g} Pa "
          f"({100 * (youngs_modulus / truth.youngs_modulus - 1):+.2f}% of the truth), nu = {poissons_ratio:.5f} "
          f"({100 * (poissons_ratio / truth.poissons_ratio - 1):+.2f}%), final cost {fit.fun:.4e}, "
          f"{evaluations} evaluations, {seconds:.2f} s ({fit.message})")
    if args.compare:
        command = [os.path.join(args.bin, "diffpd"), "run", "calibrate-plant", "--methods", args.method,
                   "--no-compare", "--json"]
        start = time.perf_counter()
        out = json.loads(subprocess.run(command, check=True, capture_output=True, text=True).stdout)
        seconds = time.perf_counter() - start
        cpp = out["fits"][0] if "fits" in out else out
        print(f"C++ + Ceres LM ({args.method}):       E = {out['youngs_modulus']:.6g} Pa, "
              f"nu = {out['poissons_ratio']:.5f}, final cost {out['final_cost']:.4e}, "
              f"{out['evaluations']} evaluations, {seconds:.2f} s (process wall time)")


if __name__ == "__main__":
    main()
