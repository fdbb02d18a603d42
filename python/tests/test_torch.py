"""diffpd.torch: rollouts as torch.autograd Functions, checked by torch.autograd.gradcheck."""

import numpy as np
import pytest

torch = pytest.importorskip("torch")

import diffpd  # noqa: E402
import diffpd.torch as dtorch  # noqa: E402
from conftest import beam_scene, tight_options  # noqa: E402

STEPS = 3


def small_simulator():
    return diffpd.Simulator(beam_scene(cells=(2, 1, 1), size=(0.04, 0.02, 0.02)), tight_options())


@pytest.fixture
def sim():
    return small_simulator()


def test_gradcheck_of_a_rollout_in_x0_v0_forces_and_material(sim):
    rest = torch.from_numpy(sim.rest_state().x.copy())
    generator = torch.Generator().manual_seed(3)
    n = sim.num_dofs
    x0 = (rest + 1e-4 * torch.randn(n, generator=generator, dtype=torch.float64)).requires_grad_()
    v0 = (0.01 * torch.randn(n, generator=generator, dtype=torch.float64)).requires_grad_()
    forces = (1e-3 * torch.randn(STEPS, n, generator=generator, dtype=torch.float64)).requires_grad_()
    # Material in scaled units, so that gradcheck's perturbation (1e-6) is relative.
    scaled_material = torch.tensor([1.0, 0.4, 1.0], dtype=torch.float64, requires_grad=True)
    scale = torch.tensor([1e5, 1.0, 1e3], dtype=torch.float64)
    weights = torch.randn(2, STEPS + 1, n, generator=generator, dtype=torch.float64)

    def function(x0, v0, forces, scaled_material):
        positions, velocities = dtorch.rollout(sim, x0, v0, external_force=forces, material=scaled_material * scale)
        # Reduce to a few outputs so the check takes a moment.
        return torch.stack([(weights[0] * positions).sum(), (weights[1] * velocities).sum()])

    # Two reverse passes of one rollout agree to rounding, not bit for bit (the
    # simulator's second factorisation after gradcheck's material perturbations).
    assert torch.autograd.gradcheck(function, (x0, v0, forces, scaled_material), eps=1e-6, atol=1e-6, rtol=1e-4,
                                    nondet_tol=1e-10)


def test_rollout_outputs_equal_the_simulator_and_share_numpy_memory(sim):
    rest = sim.rest_state()
    x0 = torch.from_numpy(rest.x.copy())
    v0 = torch.zeros_like(x0)
    positions, velocities = dtorch.rollout(sim, x0, v0, steps=STEPS)
    # A fresh simulator of the same scene: bit-identical to the first rollout.
    reference = small_simulator().simulate(rest, STEPS)
    assert positions.dtype == torch.float64 and positions.shape == (STEPS + 1, sim.num_dofs)
    np.testing.assert_array_equal(positions.numpy(), reference.positions())
    np.testing.assert_array_equal(velocities.numpy(), reference.velocities())


def test_a_torch_optimiser_recovers_an_external_force(sim):
    """Adam through the simulator finds the constant tip force that produced a target position."""
    n = sim.num_dofs
    x0 = torch.from_numpy(sim.rest_state().x.copy())
    v0 = torch.zeros(n, dtype=torch.float64)
    true_force = torch.zeros(STEPS, n, dtype=torch.float64)
    true_force[:, n - 1] = 0.05
    target, _ = dtorch.rollout(sim, x0, v0, external_force=true_force)
    tip = torch.tensor(0.0, dtype=torch.float64, requires_grad=True)
    optimiser = torch.optim.Adam([tip], lr=0.01)
    mask = torch.zeros(STEPS, n, dtype=torch.float64)
    mask[:, n - 1] = 1.0

    def loss_at(value):
        positions, _ = dtorch.rollout(sim, x0, v0, external_force=value * mask)
        return ((positions[-1] - target[-1]) ** 2).sum()

    initial = loss_at(tip).item()
    for _ in range(60):
        optimiser.zero_grad()
        loss = loss_at(tip)
        loss.backward()
        optimiser.step()
    assert loss_at(tip).item() < 1e-2 * initial
    assert tip.item() == pytest.approx(0.05, rel=0.05)
