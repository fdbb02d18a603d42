"""NumPy views: Eigen members come back as arrays sharing the object's memory."""

import gc

import numpy as np

import diffpd
from conftest import beam_scene


def test_mesh_vertices_is_a_writable_view_of_the_mesh():
    mesh = diffpd.make_box_hex_mesh(np.array([2, 1, 1], dtype=np.int32), np.array([0.2, 0.1, 0.1]))
    first = mesh.vertices
    second = mesh.vertices
    assert first.shape == (3, mesh.num_vertices) and first.dtype == np.float64
    assert np.shares_memory(first, second)
    first[2, 5] = 7.5
    assert mesh.vertices[2, 5] == 7.5
    assert mesh.elements.shape == (8, 2) and mesh.elements.dtype == np.int32


def test_state_arrays_are_views_and_outlive_their_python_handle():
    sim = diffpd.Simulator(beam_scene(), diffpd.SolverOptions())
    rollout = sim.simulate(sim.rest_state(), 2)
    last = rollout.states[-1]
    x = last.x
    assert np.shares_memory(x, rollout.states[-1].x)
    expected = x.copy()
    del last, rollout
    gc.collect()
    # The view keeps the rollout alive: its memory is still the final positions.
    np.testing.assert_array_equal(x, expected)


def test_assigning_an_array_copies_it_into_the_struct():
    state = diffpd.State(np.zeros(6), np.zeros(6))
    values = np.arange(6.0)
    state.x = values
    values[0] = 100.0
    assert state.x[0] == 0.0 and state.x[5] == 5.0


def test_gradient_vectors_are_views_of_the_result():
    sim = diffpd.Simulator(beam_scene(), diffpd.SolverOptions())
    rollout = sim.simulate(sim.rest_state(), 2)
    dx = np.zeros((3, sim.num_dofs))
    dx[-1, :] = 1.0
    gradient = sim.backward(rollout, diffpd.LossGradient(dx))
    assert np.shares_memory(gradient.x0, gradient.x0)
    gradient.x0[0] = 42.0
    assert gradient.x0[0] == 42.0
