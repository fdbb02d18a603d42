#!/usr/bin/env python3
"""Training the starfish controller (starfish-control, DiffPD Sec. 7.4) in PyTorch.

The library's controller (StripNetworkController: the 243-64-64-4 tanh
network driving 16 muscle strips through a delay line) acts inside the
closed-loop rollout; its weights are a torch tensor trained by torch.optim.Adam
with the C++ training's settings (lr 1e-3, weight decay 1e-4, gradient-norm
clip 1, learning rate falling linearly to 0 at step 1000) through
diffpd.torch.closed_loop_rollout, from the same initial weights (seed 42).
The swim loss (sum over steps of -v_z + v_x^2 + v_y^2 of the centre node's
mean velocity) is written in torch from the returned velocities.
With --compare it also runs the C++ training (`diffpd run starfish-control`)
with the same budget and prints both learning curves.

Usage: PYTHONPATH=build/python python3 python/examples/train_starfish.py [--full] [--evaluations 10] [--compare]
(default: the small instance, 40 steps; --full: the paper's 200 steps)
"""

import argparse
import json
import os
import subprocess
import time

import torch

import diffpd
import diffpd.torch as dtorch


def swim_loss(velocities, loss):
    """The C++ SwimLoss on the velocities v_1..v_K (rows of a (K+1) x 3n tensor)."""
    nodes = torch.tensor(loss.nodes)
    v = velocities[1:].reshape(velocities.shape[0] - 1, -1, 3)[:, nodes, :].mean(dim=1)
    d = torch.tensor(loss.direction, dtype=v.dtype)
    forward = v @ d
    side = v - forward[:, None] * d
    return (-forward + loss.side_weight * (side ** 2).sum(dim=1)).sum()


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--full", action="store_true")
    parser.add_argument("--evaluations", type=int, default=10)
    parser.add_argument("--method", default="pd-lbfgs")
    parser.add_argument("--seed", type=int, default=42)
    parser.add_argument("--compare", action="store_true", help="also run the C++ training (build/bin/diffpd)")
    parser.add_argument("--bin", default=os.path.join(os.path.dirname(__file__), "..", "..", "build", "bin"))
    args = parser.parse_args()

    problem = diffpd.problems.make("starfish-control")
    small = not args.full
    swimmer = problem.make_swimmer(small)
    options = problem.swimmer_options(small)
    options.method = diffpd.parse_method(args.method)
    options.time_step = swimmer.time_step
    sim = diffpd.Simulator(swimmer.scene, options)
    controller = diffpd.problems.make_swimmer_controller(swimmer, args.seed)
    rest = sim.rest_state()
    x0, v0 = torch.from_numpy(rest.x.copy()), torch.from_numpy(rest.v.copy())

    theta = torch.tensor(controller.parameters, dtype=torch.float64, requires_grad=True)
    optimiser = torch.optim.Adam([theta], lr=1e-3, betas=(0.9, 0.999), eps=1e-8, weight_decay=1e-4)
    schedule = torch.optim.lr_scheduler.LambdaLR(optimiser, lambda e: max(0.0, 1 - e / 1000))
    print(f"# starfish ({'full' if args.full else 'small'}): {sim.num_dofs} DoFs, {swimmer.steps} steps, "
          f"{controller.num_parameters} parameters, {args.method}, {args.evaluations} evaluations")
    rewards = []
    start = time.perf_counter()
    for evaluation in range(args.evaluations):
        optimiser.zero_grad()
        _, velocities = dtorch.closed_loop_rollout(sim, controller, theta, x0, v0, swimmer.steps)
        loss = swim_loss(velocities, swimmer.loss)
        loss.backward()
        torch.nn.utils.clip_grad_norm_([theta], 1.0)
        optimiser.step()
        schedule.step()
        rewards.append(-loss.item())
        print(f"python/torch evaluation {evaluation:3d}: reward {rewards[-1]: .6f}")
    with torch.no_grad():
        _, velocities = dtorch.closed_loop_rollout(sim, controller, theta, x0, v0, swimmer.steps)
        rewards.append(-swim_loss(velocities, swimmer.loss).item())
    seconds = time.perf_counter() - start
    print(f"python/torch: reward {rewards[0]:.6f} -> {rewards[-1]:.6f} after {args.evaluations} evaluations, "
          f"{seconds:.2f} s")

    if args.compare:
        command = [os.path.join(args.bin, "diffpd"), "run", "starfish-control", "--evaluations",
                   str(args.evaluations), "--method", args.method, "--seed", str(args.seed), "--no-compare",
                   "--json", "--out", os.path.join("out", "starfish-control-cpp")] + ([] if args.full else ["--small"])
        start = time.perf_counter()
        out = json.loads(subprocess.run(command, check=True, capture_output=True, text=True).stdout)
        seconds = time.perf_counter() - start
        curve = [row["reward"] for row in out["learning_curve"]]
        print(f"C++ (Adam):   reward {out['initial_reward']:.6f} -> {out['final_reward']:.6f} after "
              f"{out['evaluations']} evaluations, {out['total_s']:.2f} s ({seconds:.2f} s process wall time)")
        for evaluation, (a, b) in enumerate(zip(rewards, curve)):
            print(f"evaluation {evaluation:3d}: python {a: .6f}  C++ {b: .6f}")


if __name__ == "__main__":
    main()
