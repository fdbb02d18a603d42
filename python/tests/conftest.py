"""Shared scenes of the Python tests: small enough for seconds."""

import numpy as np
import pytest

import diffpd


def beam_scene(cells=(3, 1, 1), size=(0.06, 0.02, 0.02), youngs_modulus=1e5):
    """A beam of cells[0] x cells[1] x cells[2] hexes clamped at x = 0, under gravity."""
    mesh = diffpd.make_box_hex_mesh(np.array(cells, dtype=np.int32), np.array(size, dtype=float))
    scene = diffpd.Scene(mesh, diffpd.MaterialParameters(youngs_modulus, 0.4, 1e3))
    scene.gravity = np.array([0.0, 0.0, -9.81])
    clamped = [i for i in range(mesh.num_vertices) if mesh.vertices[0, i] == 0.0]
    scene.fix_nodes(clamped)
    return scene


def tight_options(method=diffpd.Method.NEWTON_CHOLESKY, time_step=0.01):
    """Steps converged far below finite differences' resolution."""
    return diffpd.SolverOptions(method=method, time_step=time_step, abs_tolerance=1e-12, rel_tolerance=1e-12,
                                num_threads=1)


@pytest.fixture
def beam():
    return beam_scene()
