"""The simulator from Python: gradients against central differences, tangents
against the reverse pass, and rollouts equal to the C++ program's."""

import json
import os
import subprocess

import numpy as np
import pytest

import diffpd
from conftest import beam_scene, tight_options

STEPS = 4


def final_loss(sim, x0, v0, forces, weights):
    rollout = sim.simulate(diffpd.State(x0, v0), STEPS, external_force=forces)
    return float(weights @ rollout.states[-1].x)


@pytest.fixture
def problem():
    scene = beam_scene()
    sim = diffpd.Simulator(scene, tight_options())
    rng = np.random.default_rng(7)
    weights = rng.standard_normal(sim.num_dofs)
    forces = 1e-3 * rng.standard_normal((STEPS, sim.num_dofs))
    return scene, sim, weights, forces


def test_backward_matches_central_differences_for_x0_v0_forces_and_material(problem):
    scene, sim, weights, forces = problem
    rest = sim.rest_state()
    x0, v0 = rest.x.copy(), 0.01 * np.ones(sim.num_dofs)
    rollout = sim.simulate(diffpd.State(x0, v0), STEPS, external_force=forces)
    dx = np.zeros((STEPS + 1, sim.num_dofs))
    dx[-1] = weights
    gradient = sim.backward(rollout, diffpd.LossGradient(dx))

    free = sim.num_dofs - 1  # the last node's z: not clamped
    for name, analytic, perturb, eps in [
        ("v0", gradient.v0[free], lambda e: (x0, v0 + e * np.eye(sim.num_dofs)[free], forces), 1e-5),
        ("force[1]", gradient.external_force_array()[1, free],
         lambda e: (x0, v0, forces + e * np.outer(np.eye(STEPS)[1], np.eye(sim.num_dofs)[free])), 1e-4),
    ]:
        numeric = (final_loss(sim, *perturb(eps), weights) - final_loss(sim, *perturb(-eps), weights)) / (2 * eps)
        assert analytic == pytest.approx(numeric, rel=1e-5), name

    def loss_at(youngs_modulus):
        sim.set_material(diffpd.MaterialParameters(youngs_modulus, 0.4, 1e3))
        return final_loss(sim, x0, v0, forces, weights)

    e = scene.material.youngs_modulus
    numeric = (loss_at(e * (1 + 1e-5)) - loss_at(e * (1 - 1e-5))) / (2e-5 * e)
    assert gradient.youngs_modulus == pytest.approx(numeric, rel=1e-5)


def test_tangent_along_youngs_modulus_equals_the_reverse_pass(problem):
    scene, sim, weights, forces = problem
    rollout = sim.simulate(sim.rest_state(), STEPS, external_force=forces)
    dx = np.zeros((STEPS + 1, sim.num_dofs))
    dx[-1] = weights
    gradient = sim.backward(rollout, diffpd.LossGradient(dx))
    tangents = sim.tangents(rollout, [diffpd.InputDirection.youngs_modulus_direction()])
    assert tangents.num_steps == STEPS and tangents.num_directions == 1
    assert float(weights @ tangents.dx[-1][:, 0]) == pytest.approx(gradient.youngs_modulus, rel=1e-8)


def test_list_of_step_inputs_and_array_inputs_give_the_same_rollout(problem):
    scene, sim, weights, forces = problem
    a = sim.simulate(sim.rest_state(), [diffpd.StepInput(f) for f in forces])
    # A fresh simulator: the first rollouts of two simulators of one scene are bit-identical.
    sim = diffpd.Simulator(scene, tight_options())
    b = sim.simulate(sim.rest_state(), STEPS, external_force=forces)
    np.testing.assert_array_equal(a.positions(), b.positions())
    assert a.num_steps == STEPS and a.positions().shape == (STEPS + 1, sim.num_dofs)


def test_every_solver_option_field_is_settable_and_round_trips():
    fields = [name for name in dir(diffpd.SolverOptions) if not name.startswith("_") and name != "validate"]
    assert len(fields) == 28
    defaults = diffpd.SolverOptions()
    assert defaults.method == diffpd.Method.PD and defaults.time_step == 0.01
    assert defaults.pd_factor_copy_max_bytes == 4 * 2**30 and defaults.svd_warm_start
    assert defaults.adjoint_solver == diffpd.AdjointSolver.AUTO


@pytest.mark.skipif(not hasattr(diffpd, "problems"), reason="built without the problems library")
def test_problem_names_are_those_of_diffpd_list():
    binary = os.path.join(os.environ.get("DIFFPD_BIN_DIR", ""), "diffpd")
    listed = json.loads(subprocess.run([binary, "list", "--json"], check=True, capture_output=True, text=True).stdout)
    names = [entry["name"] for entry in listed]
    assert diffpd.problems.names() == names


@pytest.mark.skipif(not hasattr(diffpd, "problems"), reason="built without the problems library")
def test_falling_cube_rollout_equals_the_cpp_programs():
    binary = os.path.join(os.environ.get("DIFFPD_BIN_DIR", ""), "diffpd")
    steps = 3
    out = subprocess.run([binary, "run", "falling-cube", "--steps", str(steps), "--method", "newton-cholesky",
                          "--threads", "1", "--rtol", "1e-6", "--json"], check=True, capture_output=True, text=True).stdout
    reference = json.loads(out)["step_table"]

    problem = diffpd.problems.make("falling-cube")
    options = diffpd.SolverOptions(method=diffpd.Method.NEWTON_CHOLESKY, time_step=problem.default_time_step,
                                   rel_tolerance=1e-6, num_threads=1)
    sim = diffpd.Simulator(problem.make_scene(), options)
    state = problem.initial_state(sim)
    mass = sim.lumped_mass()
    rest = sim.rest_state().x.reshape(-1, 3)
    for k, step_input in enumerate(problem.inputs(sim, steps)):
        state, report = sim.step(state, step_input)
        displacement = np.linalg.norm(state.x.reshape(-1, 3) - rest, axis=1).max()
        kinetic = 0.5 * float(state.v @ (mass * state.v))
        row = reference[k]
        assert report.iterations == row["iterations"]
        assert displacement == pytest.approx(row["max_displacement"], rel=1e-12)
        assert kinetic == pytest.approx(row["kinetic_energy"], rel=1e-12)


def test_a_diverging_semi_implicit_step_reports_the_stability_limit_explicit_stable_time_step_gives():
    scene = beam_scene()
    probe = diffpd.Simulator(scene, diffpd.SolverOptions(method=diffpd.Method.SEMI_IMPLICIT, time_step=1e-4))
    limit = probe.explicit_stable_time_step(probe.rest_state().x)
    assert 0 < limit < 1e-2
    options = diffpd.SolverOptions(method=diffpd.Method.SEMI_IMPLICIT, time_step=1.5 * limit, num_threads=1)
    sim = diffpd.Simulator(scene, options)
    with pytest.raises(diffpd.SolverError, match=r"above semi-implicit Euler's stability limit at the rest shape, "
                                                 r"about ([0-9.e+-]+) s") as info:
        sim.simulate(sim.rest_state(), 200)
    reported = float(info.value.args[0].split("about ")[1].split(" s")[0])
    assert reported == pytest.approx(limit, rel=1e-5)


def test_holding_a_rollouts_own_quad_faces_reproduces_it_and_a_wrong_hold_is_refused():
    scene = beam_scene()
    scene.dirichlet = diffpd.DirichletBoundary()
    scene.gravity = np.zeros(3)
    water = diffpd.QuadHydrodynamics()
    water.quads = diffpd.boundary_quads(scene.mesh)
    scene.quad_hydrodynamics = water
    options = diffpd.SolverOptions(method=diffpd.Method.NEWTON_CHOLESKY)
    options.svd_warm_start = False  # a step's result depends on its state and input alone
    sim = diffpd.Simulator(scene, options)
    v = np.zeros(sim.num_dofs)
    v[0::3] = 0.5  # gliding along x: the side faces move along their planes
    start = diffpd.State(sim.rest_state().x.copy(), v)
    free_next, _ = sim.step(start, diffpd.StepInput())
    wetted = diffpd.wetted_quads(water, start.x, start.v)
    assert len(wetted) == water.quads.shape[1]
    assert 0 < sum(wetted) < len(wetted)
    held = diffpd.StepInput()
    held.wetted_quads = wetted
    assert held.wetted_quads == wetted
    held_next, _ = sim.step(start, held)
    assert np.array_equal(held_next.x, free_next.x)
    held.wetted_quads = [False] * len(wetted)  # no face feels the water
    dry_next, _ = sim.step(start, held)
    assert not np.array_equal(dry_next.x, free_next.x)
    held.wetted_quads = wetted[:-1]
    with pytest.raises(diffpd.InvalidInputError) as info:
        sim.step(start, held)
    faces = len(wetted)
    assert str(info.value) == (
        f"wetted_quads has {faces - 1} entries, expected {faces} (one per quad_hydrodynamics face)"
    )
    with pytest.raises(diffpd.InvalidInputError) as info:
        diffpd.wetted_quads(water, start.x[:-3], start.v)
    assert str(info.value) == (
        f"wetted_quads: x and v must have the same length, a multiple of 3 (got {sim.num_dofs - 3} and {sim.num_dofs})"
    )
    short_x = start.x[:-3]
    with pytest.raises(diffpd.InvalidInputError) as info:
        diffpd.wetted_quads(water, short_x, start.v[:-3])
    nodes = sim.num_dofs // 3 - 1
    assert str(info.value) == (
        f"wetted_quads: water.quads has node indices outside [0, {nodes}) for x of {3 * nodes} entries"
    )
