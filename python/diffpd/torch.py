"""torch.autograd Functions over DiffPD rollouts.

rollout(simulator, x0, v0, ...) runs K steps forward with Simulator.simulate
and returns the positions and velocities of states 0..K, two (K+1) x 3n
tensors; their gradient is computed by Simulator.backward (one reverse pass
for the whole rollout), for the initial state, the per-step external forces
and muscle activations and the base material (E, nu, rho). Any PyTorch loss of
the trajectory can therefore be minimised with any torch optimiser.

closed_loop_rollout(simulator, controller, parameters, x0, v0, steps) does the
same for a rollout driven by a library controller (e.g.
StripNetworkController) whose parameters are a tensor; its gradient includes
dL/dparameters (Simulator.backward with the controller).

Tensors may be of any floating dtype and device: the simulation runs in
float64 on the CPU, outputs are float64 CPU tensors sharing the memory of
NumPy arrays, gradients come back in each input's dtype and device.
"""

import numpy as np
import torch

from . import _diffpd as _native

__all__ = ["Rollout", "ClosedLoopRollout", "rollout", "closed_loop_rollout"]


def _to_numpy(tensor):
    return tensor.detach().to(device="cpu", dtype=torch.float64).numpy()


def _like(array, tensor):
    if tensor is None:
        return None
    return torch.from_numpy(np.ascontiguousarray(array)).to(device=tensor.device, dtype=tensor.dtype)


def _material(values):
    e, nu, rho = (float(v) for v in _to_numpy(values))
    return _native.MaterialParameters(e, nu, rho)


def _loss_gradient(grad_positions, grad_velocities, rows):
    dx = None if grad_positions is None else _to_numpy(grad_positions)
    dv = None if grad_velocities is None else _to_numpy(grad_velocities)
    if dx is None and dv is None:
        dx = np.zeros((rows, 0))
    return _native.LossGradient(dx, dv)


def _set_material(simulator, material):
    current = simulator.scene.material
    if (current.youngs_modulus, current.poissons_ratio, current.density) != (
            material.youngs_modulus, material.poissons_ratio, material.density):
        simulator.set_material(material)


class Rollout(torch.autograd.Function):
    """(positions, velocities) of an open-loop rollout; see rollout()."""

    @staticmethod
    def forward(ctx, simulator, steps, x0, v0, external_force, activation, material):
        if material is not None:
            _set_material(simulator, _material(material))
        initial = _native.State(_to_numpy(x0), _to_numpy(v0))
        result = simulator.simulate(
            initial, steps,
            external_force=None if external_force is None else _to_numpy(external_force),
            activation=None if activation is None else _to_numpy(activation))
        # An output the loss does not use gives None, not zeros (no zero rows to convert and add).
        ctx.set_materialize_grads(False)
        ctx.simulator = simulator
        ctx.rollout = result
        ctx.inputs = (x0, v0, external_force, activation, material)
        return torch.from_numpy(result.positions()), torch.from_numpy(result.velocities())

    @staticmethod
    def backward(ctx, grad_positions, grad_velocities):
        simulator, result = ctx.simulator, ctx.rollout
        x0, v0, external_force, activation, material = ctx.inputs
        # Another forward may have changed the simulator's material since.
        _set_material(simulator, result.material)
        gradient = simulator.backward(result, _loss_gradient(grad_positions, grad_velocities, result.num_steps + 1))
        grad_force = grad_activation = grad_material = None
        if external_force is not None and ctx.needs_input_grad[4]:
            grad_force = _like(gradient.external_force_array().reshape(external_force.shape), external_force)
        if activation is not None and ctx.needs_input_grad[5]:
            grad_activation = _like(gradient.activation_array().reshape(activation.shape), activation)
        if material is not None and ctx.needs_input_grad[6]:
            grad_material = _like(
                np.array([gradient.youngs_modulus, gradient.poissons_ratio, gradient.density]), material)
        return (None, None, _like(gradient.x0, x0), _like(gradient.v0, v0), grad_force, grad_activation,
                grad_material)


class ClosedLoopRollout(torch.autograd.Function):
    """(positions, velocities) of a closed-loop rollout; see closed_loop_rollout()."""

    @staticmethod
    def forward(ctx, simulator, controller, steps, parameters, x0, v0):
        acting = controller.clone()
        acting.set_parameters(_to_numpy(parameters))
        initial = _native.State(_to_numpy(x0), _to_numpy(v0))
        result = simulator.simulate(initial, acting, steps)
        ctx.set_materialize_grads(False)
        ctx.simulator = simulator
        ctx.controller = acting
        ctx.rollout = result
        ctx.inputs = (parameters, x0, v0)
        return torch.from_numpy(result.positions()), torch.from_numpy(result.velocities())

    @staticmethod
    def backward(ctx, grad_positions, grad_velocities):
        simulator, result = ctx.simulator, ctx.rollout
        parameters, x0, v0 = ctx.inputs
        _set_material(simulator, result.material)
        gradient = simulator.backward(result, _loss_gradient(grad_positions, grad_velocities, result.num_steps + 1),
                                      ctx.controller)
        return (None, None, None, _like(gradient.controller_parameters, parameters), _like(gradient.x0, x0),
                _like(gradient.v0, v0))


def rollout(simulator, x0, v0, external_force=None, activation=None, material=None, steps=None):
    """Simulates K steps and returns (positions, velocities), each (K+1) x 3n.

    x0, v0: 3n tensors (the initial state). external_force: K x 3n (N) or
    None; activation: K x (muscles) or None; material: a 3-vector
    (youngs_modulus Pa, poissons_ratio, density kg/m^3) that replaces the
    simulator's base material, or None to keep it. steps: K, needed only when
    neither external_force nor activation is given. Every tensor argument may
    require grad.
    """
    if steps is None:
        if external_force is not None:
            steps = external_force.shape[0]
        elif activation is not None:
            steps = activation.shape[0]
        else:
            raise _native.InvalidInputError(
                "rollout: steps is needed when neither external_force nor activation is given")
    return Rollout.apply(simulator, int(steps), x0, v0, external_force, activation, material)


def closed_loop_rollout(simulator, controller, parameters, x0, v0, steps):
    """Closed loop: `controller` (a copy, with `parameters`) acts at each of `steps` steps.

    Returns (positions, velocities), each (steps+1) x 3n; gradients flow to
    parameters (controller.num_parameters entries), x0 and v0.
    """
    return ClosedLoopRollout.apply(simulator, controller, int(steps), parameters, x0, v0)
