"""The library's exceptions reach Python as diffpd.InvalidInputError / SolverError with its messages."""

import numpy as np
import pytest

import diffpd
from conftest import beam_scene


def test_invalid_options_raise_invalid_input_error_with_the_library_message():
    options = diffpd.SolverOptions(time_step=-1.0)
    with pytest.raises(diffpd.InvalidInputError) as info:
        options.validate()
    assert str(info.value) == "solver options: time_step = -1 is invalid: must be finite and > 0 (s)"
    # The hierarchy: a diffpd.Error and a ValueError.
    assert isinstance(info.value, diffpd.Error)
    assert isinstance(info.value, ValueError)


def test_simulator_constructor_rejects_a_bad_material_with_the_library_message():
    scene = beam_scene()
    scene.material = diffpd.MaterialParameters(0.0, 0.4, 1e3)
    with pytest.raises(diffpd.InvalidInputError, match=r"^.*youngs_modulus = 0 is invalid: must be finite and > 0 \(Pa\)$"):
        diffpd.Simulator(scene, diffpd.SolverOptions())


def test_fix_nodes_out_of_range_names_the_node_and_leaves_the_scene_unchanged():
    scene = beam_scene()
    before = list(scene.dirichlet.dofs)
    n = scene.mesh.num_vertices
    with pytest.raises(diffpd.InvalidInputError) as info:
        scene.fix_nodes([99])
    assert str(info.value) == f"FixNodes: node 99 is out of range [0, {n})"
    assert scene.dirichlet.dofs == before


def test_simulate_with_a_wrongly_sized_force_raises_instead_of_crashing():
    sim = diffpd.Simulator(beam_scene(), diffpd.SolverOptions())
    with pytest.raises(diffpd.InvalidInputError):
        sim.simulate(sim.rest_state(), 2, external_force=np.zeros((2, 5)))


def test_exploding_semi_implicit_step_raises_solver_error_with_status_diverged():
    options = diffpd.SolverOptions(method=diffpd.Method.SEMI_IMPLICIT, time_step=1e3)
    sim = diffpd.Simulator(beam_scene(), options)
    with pytest.raises(diffpd.SolverError) as info:
        sim.simulate(sim.rest_state(), 5)
    assert info.value.status == diffpd.SolverStatus.DIVERGED
    assert isinstance(info.value, RuntimeError)
    assert isinstance(info.value, diffpd.Error)


def test_parse_method_lists_valid_names_and_round_trips_str():
    for method in diffpd.Method.__members__.values():
        assert diffpd.parse_method(str(method)) == method
    with pytest.raises(diffpd.InvalidInputError):
        diffpd.parse_method("euler")


def test_unknown_solver_option_keyword_is_a_type_error():
    with pytest.raises(TypeError, match="SolverOptions has no field 'timestep'"):
        diffpd.SolverOptions(timestep=0.01)
