"""Closed loop from Python: the library's network controller, its gradients and the torch Function."""

import numpy as np
import pytest

import diffpd
from conftest import beam_scene, tight_options

STEPS = 3


def controlled_beam():
    """A clamped beam with two muscle strips on its top and bottom rows, driven by one network channel."""
    scene = beam_scene(cells=(4, 1, 2), size=(0.08, 0.02, 0.04))
    # Elements (i ny + j) nz + k: k = 0 the bottom row, k = 1 the top row.
    strips = [diffpd.MuscleStrip([2 * i for i in range(4)]), diffpd.MuscleStrip([2 * i + 1 for i in range(4)])]
    strip_muscles = scene.add_muscle_strips(strips)
    delay_line = diffpd.MuscleDelayLine(strip_muscles, len(scene.muscles))
    observation = diffpd.NodeObservation()
    observation.reference_node = 0
    observation.nodes = [scene.mesh.num_vertices - 1]
    network = diffpd.Mlp([observation.size, 4, 1], diffpd.MlpNonlinearity.TANH, diffpd.MlpNonlinearity.TANH)
    network.initialize_orthogonal(5, 5.0 / 3.0)
    controller = diffpd.StripNetworkController(network, observation, delay_line,
                                               [diffpd.StripDrive(0, 1), diffpd.StripDrive(0, -1)],
                                               scene.mesh.num_vertices)
    return scene, controller


def test_mlp_backward_matches_central_differences():
    network = diffpd.Mlp([3, 5, 2])
    network.initialize_orthogonal(1, 1.0)
    x = np.array([0.3, -0.2, 0.5])
    g = np.array([1.0, -2.0])
    output, tape = network.forward(x)
    np.testing.assert_array_equal(output, network.evaluate(x))
    g_input, g_parameters = network.backward(tape, g)
    for i in range(3):
        e = 1e-6 * np.eye(3)[i]
        numeric = (g @ network.evaluate(x + e) - g @ network.evaluate(x - e)) / 2e-6
        assert g_input[i] == pytest.approx(numeric, rel=1e-7, abs=1e-10)
    theta = network.parameters.copy()
    for p in (0, 7, network.num_parameters - 1):
        values = []
        for sign in (1, -1):
            network.set_parameters(theta + sign * 1e-6 * np.eye(network.num_parameters)[p])
            values.append(g @ network.evaluate(x))
        assert g_parameters[p] == pytest.approx((values[0] - values[1]) / 2e-6, rel=1e-7, abs=1e-10)


def test_closed_loop_controller_gradient_matches_central_differences():
    scene, controller = controlled_beam()
    sim = diffpd.Simulator(scene, tight_options())
    rollout = sim.simulate(sim.rest_state(), controller, STEPS)
    assert rollout.closed_loop and rollout.num_steps == STEPS
    weights = np.random.default_rng(1).standard_normal(sim.num_dofs)
    dx = np.zeros((STEPS + 1, sim.num_dofs))
    dx[-1] = weights
    gradient = sim.backward(rollout, diffpd.LossGradient(dx), controller)
    theta = controller.parameters
    assert gradient.controller_parameters.shape == theta.shape
    for p in (0, 3, controller.num_parameters - 1):
        values = []
        for sign in (1, -1):
            perturbed = controller.clone()
            perturbed.set_parameters(theta + sign * 1e-6 * np.eye(controller.num_parameters)[p])
            fresh = diffpd.Simulator(scene, tight_options())
            values.append(weights @ fresh.simulate(fresh.rest_state(), perturbed, STEPS).states[-1].x)
        numeric = (values[0] - values[1]) / 2e-6
        assert gradient.controller_parameters[p] == pytest.approx(numeric, rel=1e-5, abs=1e-12)


def test_gradcheck_of_a_closed_loop_rollout_in_the_controller_parameters():
    torch = pytest.importorskip("torch")
    import diffpd.torch as dtorch
    scene, controller = controlled_beam()
    sim = diffpd.Simulator(scene, tight_options())
    rest = sim.rest_state()
    x0 = torch.from_numpy(rest.x.copy())
    v0 = torch.zeros_like(x0)
    weights = torch.randn(STEPS + 1, sim.num_dofs, generator=torch.Generator().manual_seed(2), dtype=torch.float64)
    theta = torch.tensor(controller.parameters, requires_grad=True)

    def function(theta):
        positions, velocities = dtorch.closed_loop_rollout(sim, controller, theta, x0, v0, STEPS)
        return torch.stack([(weights * positions).sum(), (weights * velocities).sum()])

    assert torch.autograd.gradcheck(function, (theta,), eps=1e-6, atol=1e-6, rtol=1e-4, nondet_tol=1e-10)
