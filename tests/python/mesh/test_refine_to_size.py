"""Mesh.refine_uniform(target_cells=...) (issue 34 item 5): the fewest uniform levels that reach a
cell count, and the growth per level its docstring states."""
from pathlib import Path

import numpy as np
import pytest
from expected_errors import refused

import snede
from snede import meshing

MESHES = Path(__file__).resolve().parents[3] / "meshes"


def counts_per_level(make, levels):
    mesh = make()
    counts = [mesh.n_cells]
    for _ in range(levels):
        mesh.refine_uniform(1)
        counts.append(mesh.n_cells)
    return counts


@pytest.mark.parametrize("target, levels", [(48, 0), (49, 1), (96, 1), (1000, 5), (1536, 5), (1537, 6)])
def test_a_structured_box_takes_the_fewest_levels_that_reach_the_target(target, levels):
    """box 2×2×2: 48 cells, doubled by each level."""
    mesh = meshing.box((1.0, 1.0, 1.0), (2, 2, 2))
    split = mesh.refine_uniform(target_cells=target)
    expected = meshing.box((1.0, 1.0, 1.0), (2, 2, 2))
    assert split == expected.refine_uniform(levels)
    assert mesh.n_cells == expected.n_cells == 48 * 2**levels
    np.testing.assert_array_equal(mesh.cells, expected.cells)


def test_an_unstructured_mesh_stops_at_the_first_level_past_the_target():
    counts = counts_per_level(lambda: snede.Mesh.read(MESHES / "cylinder_small.msh"), 2)
    mesh = snede.Mesh.read(MESHES / "cylinder_small.msh")
    mesh.refine_uniform(target_cells=counts[1] + 1)
    assert mesh.n_cells == counts[2]
    mesh.validate()


def test_growth_per_level_is_what_the_docstring_says():
    """About 3.9× at the first level of a gmsh cylinder (longest-edge bisection), 3.3× at the
    second; 2.2–2.4× in 2D."""
    counts = counts_per_level(lambda: snede.Mesh.read(MESHES / "cylinder_small.msh"), 2)
    growth = np.diff(np.log(counts))
    assert counts[0] == 1125 and 3.7 < np.exp(growth[0]) < 4.1 and 3.1 < np.exp(growth[1]) < 3.5
    assert "about 3.3× per level" in snede.Mesh.refine_uniform.__doc__


def test_a_body_on_the_mesh_carries_its_state_through_every_level():
    """A linear displacement is interpolated exactly at the new midpoints."""
    mesh = meshing.box((1.0, 1.0, 1.0), (2, 2, 2))
    body = snede.Body(mesh, snede.LinearElastic(1e4, 0.3))

    def linear(x):
        return x @ np.array([[0.1, 0.0, 0.2], [0.0, -0.1, 0.0], [0.3, 0.0, 0.1]])
    body.displacement = linear(mesh.points)
    mesh.refine_uniform(target_cells=400)
    assert mesh.n_cells == 768
    np.testing.assert_allclose(body.displacement, linear(mesh.points), atol=1e-15)


def test_a_mesh_already_large_enough_is_left_alone():
    mesh = meshing.rectangle((1.0, 1.0), (2, 2))
    assert mesh.refine_uniform(target_cells=8) == 0 and mesh.n_cells == 8


@pytest.mark.parametrize("kwargs, message", [
    ({"levels": 2, "target_cells": 100}, "give levels or target_cells, not both (got levels=2, target_cells=100)"),
    ({"target_cells": 0}, "target_cells must be at least 1, got 0"),
    ({"target_cells": 1.5}, "target_cells must be a positive integer in 1..2147483647, got 1.5 (float)"),
    ({"target_cells": True}, "target_cells must be a positive integer in 1..2147483647, got True (bool)"),
    ({"target_cells": 2**31}, "target_cells must be at most 2147483647"),
])
def test_bad_targets_are_refused_by_name(kwargs, message):
    mesh = meshing.rectangle((1.0, 1.0), (2, 2))
    refused(lambda: mesh.refine_uniform(**kwargs), message)
    assert mesh.n_cells == 8
