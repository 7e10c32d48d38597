"""The learning-free baseline of skeleton prediction: the nearest training character's skeleton.

Issue 9's baseline for ``eval rig``: among training characters (already in
RigNet's normalised frame, :class:`~..dataset.sample.CharacterSample`), the
one whose normalised surface is closest to the target's normalised surface
by the symmetric Chamfer distance, its deform skeleton mapped from its
bounding box onto the target's.

1. The target mesh is normalised as the samples are
   (:func:`~..dataset.normalise.normalisation_transform`), without a facing
   turn: a bare mesh has no bone names to tell its left from its right, so
   it is taken to face -Y as the predictor expects.
2. :data:`SURFACE_POINTS` points are drawn on each normalised surface,
   uniformly by area with a fixed seed (:func:`surface_points`), so the
   distance does not depend on how finely either mesh is tessellated and
   the choice is reproducible.
3. The chosen character's deform bones (heads and tails; names and parents
   kept) are mapped by the per-axis affine map taking its normalised
   bounding box onto the target's, then back to the target's world space.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Collection, Sequence

import numpy as np

from ..dataset.normalise import apply_transform, normalisation_transform
from ..dataset.sample import CharacterSample
from ..errors import InputError
from ..evaluation.skeleton_metrics import symmetric_chamfer
from ..geometry.bounding_box import bounding_box
from ..geometry.normals import triangle_double_areas
from ..types import Mesh, Skeleton
from .surface_fit import box_axis_map

#: Points drawn on each normalised surface for the Chamfer distance. On a
#: character of largest side 1, 2,000 points are about 2 cm apart on a
#: 1.7 m human: enough to tell a biped from a quadruped or a long tail, and
#: each comparison costs a few milliseconds.
SURFACE_POINTS = 2_000
#: Seed of the surface sampling: the same mesh always gives the same points.
SAMPLING_SEED = 0


@dataclass(frozen=True)
class NearestCharacter:
    """Result of :func:`nearest_character`.

    Attributes
    ----------
    skeleton : Skeleton
        The chosen character's deform bones, in the target mesh's world space.
    name : str
        The chosen training character (:attr:`CharacterSample.name`).
    distance : float
        Symmetric Chamfer distance between the two normalised surfaces, in
        units of the largest side of the bounding box.
    """

    skeleton: Skeleton
    name: str
    distance: float

    @property
    def note(self) -> str:
        """What was chosen, for an evaluation's notes."""
        return f"nearest training character: {self.name} (surface Chamfer distance {self.distance:.4f})"


def surface_points(vertices: np.ndarray, triangles: np.ndarray, count: int = SURFACE_POINTS,
                   seed: int = SAMPLING_SEED) -> np.ndarray:
    """Points drawn uniformly by area on a triangle surface.

    Each point picks a triangle with probability proportional to its area,
    then a uniform point inside it (the square-root barycentric rule).

    Parameters
    ----------
    vertices : (n, 3) float64 array
    triangles : (m, 3) int array
    count : int, points to draw
    seed : int, seed of ``numpy.random.default_rng``

    Returns
    -------
    points : (count, 3) float64 array

    Raises
    ------
    InputError
        When the surface has no area (no triangles, or all degenerate).
    """
    vertices = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    triangles = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    areas = triangle_double_areas(vertices, triangles) if len(triangles) else np.zeros(0)
    total = float(areas.sum())
    if not np.isfinite(total) or total <= 0.0:
        raise InputError("The mesh has no faces with an area, so there is no surface to compare with the training "
                         "characters.")
    rng = np.random.default_rng(seed)
    chosen = triangles[rng.choice(len(triangles), size=int(count), p=areas / total)]
    root, second = np.sqrt(rng.random(int(count)))[:, None], rng.random(int(count))[:, None]
    corners = vertices[chosen]
    return (1.0 - root) * corners[:, 0] + root * (1.0 - second) * corners[:, 1] + root * second * corners[:, 2]


def box_map(points: np.ndarray, source_vertices: np.ndarray, target_vertices: np.ndarray) -> np.ndarray:
    """``points`` moved by the per-axis affine map taking the bounding box of
    ``source_vertices`` onto that of ``target_vertices``
    (:func:`.surface_fit.box_axis_map`: along an axis where the source box is
    flat, points are only shifted).

    Parameters
    ----------
    points : (k, 3) float64 array
    source_vertices, target_vertices : (n, 3), (m, 3) float64 arrays, n, m >= 1

    Returns
    -------
    mapped : (k, 3) float64 array
    """
    return box_axis_map(bounding_box(source_vertices), bounding_box(target_vertices))(points)


def nearest_character(mesh: Mesh, pool: Sequence[CharacterSample], exclude: Collection[str] = ()) -> NearestCharacter:
    """The skeleton of the training character nearest to ``mesh``, fitted to its bounding box.

    Parameters
    ----------
    mesh : Mesh, world space, upright (+Z), facing -Y
    pool : sequence of CharacterSample
        The characters to choose from, normalised (the training samples).
    exclude : collection of str
        Names never chosen (the validation characters), even when in ``pool``.

    Returns
    -------
    NearestCharacter
        Ties go to the first character in ``pool`` order.

    Raises
    ------
    InputError
        When the mesh has no surface, or no character of ``pool`` is left
        after ``exclude`` or has deform bones.
    """
    excluded = set(exclude)
    candidates = [sample for sample in pool if sample.name not in excluded and sample.deform.any()]
    if not candidates:
        raise InputError("No training character with deform bones to choose a skeleton from (the pool is empty once "
                         "the validation characters are left out).")
    to_normalised = normalisation_transform(mesh.vertices)
    normalised = apply_transform(mesh.vertices, to_normalised)
    target_points = surface_points(normalised, mesh.triangles)
    distances = [symmetric_chamfer(target_points, surface_points(sample.vertices, sample.triangles))
                 for sample in candidates]
    best = int(np.argmin(distances))
    chosen = candidates[best]
    bones = chosen.skeleton.deform_subset()
    to_world = np.linalg.inv(to_normalised)

    def fitted(points: np.ndarray) -> np.ndarray:
        return apply_transform(box_map(points, chosen.vertices, normalised), to_world)

    skeleton = Skeleton(fitted(bones.joints), bones.parents, bones.names, fitted(bones.tails), bones.deform)
    return NearestCharacter(skeleton, chosen.name, float(distances[best]))
