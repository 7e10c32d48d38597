"""core.geometry.flatness: a pancake is flat, a body or a snake is not."""

import numpy as np
import pytest

from autorig_addon.core.geometry.flatness import FLAT_THICKNESS_RATIO, flatness
from autorig_addon.core.procedural import generate_character


def tube_along(path: np.ndarray, radius: float, segments: int = 12):
    """Vertices and triangles of a tube of ``radius`` along the (k, 3) ``path`` (its rings face along the path)."""
    tangents = np.gradient(path, axis=0)
    tangents /= np.linalg.norm(tangents, axis=1, keepdims=True)
    vertices = []
    for point, tangent in zip(path, tangents):
        side = np.cross(tangent, [0.0, 0.0, 1.0])
        side = side / np.linalg.norm(side) if np.linalg.norm(side) > 1e-9 else np.array([1.0, 0.0, 0.0])
        up = np.cross(side, tangent)
        for angle in np.linspace(0.0, 2.0 * np.pi, segments, endpoint=False):
            vertices.append(point + radius * (np.cos(angle) * side + np.sin(angle) * up))
    triangles = []
    for ring in range(len(path) - 1):
        for step in range(segments):
            a, b = ring * segments + step, ring * segments + (step + 1) % segments
            triangles += [[a, b, b + segments], [a, b + segments, a + segments]]
    return np.array(vertices), np.array(triangles)


def test_a_biped_squashed_by_its_scale_is_flat_and_the_biped_is_not():
    mesh = generate_character(0, "biped").mesh
    assert not flatness(mesh.vertices, mesh.triangles).is_flat
    squashed = flatness(mesh.vertices * [1.0, 1.0, 0.019], mesh.triangles)
    assert squashed.is_flat and squashed.thickness_ratio < FLAT_THICKNESS_RATIO
    assert abs(squashed.axis[2]) > 0.999  # the squashed axis
    assert squashed.facing_share > 0.9


def test_a_snake_stretched_out_or_coiled_flat_on_the_ground_is_not_flat():
    turns = np.linspace(0.0, 6.0 * np.pi, 400)
    coil = np.column_stack([(0.2 + 0.02 * turns) * np.cos(turns), (0.2 + 0.02 * turns) * np.sin(turns),
                            np.zeros_like(turns)])
    straight = np.column_stack([np.linspace(0.0, 2.0, 100), np.zeros(100), np.zeros(100)])
    for path in (coil, straight):
        shape = flatness(*tube_along(path, 0.03))
        assert not shape.is_flat
    # The coil is as thin as a pancake; its surface turns all around the tube.
    coiled = flatness(*tube_along(coil, 0.03))
    assert coiled.thickness_ratio < FLAT_THICKNESS_RATIO and coiled.facing_share < 0.5


def test_a_sheet_is_flat_with_its_extents_thinnest_first():
    square = np.array([[0, 0, 0], [2, 0, 0], [2, 1, 0], [0, 1, 0]], dtype=float)
    shape = flatness(square, np.array([[0, 1, 2], [0, 2, 3]]))
    assert shape.is_flat and shape.facing_share == 1.0
    assert (shape.thickness, shape.width, shape.length) == pytest.approx((0.0, 1.0, 2.0))


@pytest.mark.parametrize("kind", ["biped", "quadruped"])
def test_no_procedural_character_is_flat(kind):
    for seed in range(6):
        mesh = generate_character(seed, kind).mesh
        assert not flatness(mesh.vertices, mesh.triangles).is_flat, seed
