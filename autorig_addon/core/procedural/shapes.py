"""Primitive surfaces the generator builds characters from.

Every closed shape here is watertight and faces outward (counter-clockwise
seen from outside); open sheets face the direction they are given. Shapes
are placed with a frame: a (3, 3) array whose columns are the shape's own
x, y and z axes in world space (:func:`.frames.axis_frame`).
"""

from __future__ import annotations

import numpy as np

from .frames import normalized

#: Fewest and most vertices around one ring of a tube or ellipsoid.
MIN_RING_SEGMENTS = 6
MAX_RING_SEGMENTS = 16
#: Fewest and most rings around the core circle of a torus.
MIN_TORUS_SEGMENTS = 12
MAX_TORUS_SEGMENTS = 40


def ring_segments(radius: float, spacing: float) -> int:
    """Even vertex count around a ring of ``radius`` for edges near ``spacing``
    (clamped to :data:`MIN_RING_SEGMENTS` .. :data:`MAX_RING_SEGMENTS`)."""
    count = int(np.clip(np.ceil(2.0 * np.pi * radius / spacing), MIN_RING_SEGMENTS, MAX_RING_SEGMENTS))
    return count + (count % 2)


def grid_samples(minimum: int, length: float, spacing: float) -> int:
    """Samples along ``length`` for gaps near ``spacing``, at least ``minimum``."""
    return max(minimum, int(np.ceil(length / spacing)) + 1)


def lathe(centres, tangents, normals, radii, segments, start_pole=None, end_pole=None, phase=0.0):
    """Rings swept along a curve, optionally closed by a pole at each end.

    Parameters
    ----------
    centres, tangents, normals : (k, 3) float64 arrays
        Ring centres, unit ring axes and unit in-plane reference directions.
    radii : (k, 2) float64 array
        Ring semi-axes along ``normals`` and along ``tangents x normals``.
    segments : int
        Vertices per ring.
    start_pole, end_pole : (3,) float64 array or None
        Extra vertex closing the first / last ring with a fan.
    phase : float
        Angle (radians) of each ring's first vertex from ``normals``.

    Returns
    -------
    vertices : (k * segments [+ 2], 3) float64 array
    triangles : (t, 3) int64 array
        Counter-clockwise seen from outside (outside = away from the axis,
        or beyond the poles).
    ring : (v,) int64 array
        Ring index of each vertex (poles belong to the ring they close).
    """
    count = len(centres)
    binormals = np.cross(tangents, normals)
    angles = phase + 2.0 * np.pi * np.arange(segments) / segments
    rings = (
        centres[:, None, :]
        + (radii[:, 0, None] * np.cos(angles)[None, :])[:, :, None] * normals[:, None, :]
        + (radii[:, 1, None] * np.sin(angles)[None, :])[:, :, None] * binormals[:, None, :]
    )
    vertices = [rings.reshape(-1, 3)]
    ring = [np.repeat(np.arange(count), segments)]
    j = np.arange(segments)
    j_next = (j + 1) % segments
    i = np.arange(count - 1)[:, None]
    a, b = i * segments + j, i * segments + j_next
    c, d = (i + 1) * segments + j_next, (i + 1) * segments + j
    triangles = [np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)]
    next_index = count * segments
    if start_pole is not None:
        vertices.append(np.asarray(start_pole, dtype=np.float64)[None, :])
        ring.append(np.zeros(1, dtype=np.int64))
        triangles.append(np.stack([np.full(segments, next_index), j_next, j], -1))
        next_index += 1
    if end_pole is not None:
        last = (count - 1) * segments
        vertices.append(np.asarray(end_pole, dtype=np.float64)[None, :])
        ring.append(np.full(1, count - 1, dtype=np.int64))
        triangles.append(np.stack([last + j, last + j_next, np.full(segments, next_index)], -1))
    return np.concatenate(vertices), np.concatenate(triangles).astype(np.int64), np.concatenate(ring)


def ellipsoid_geometry(centre, radii, frame, spacing, cut_angle=0.0):
    """Closed ellipsoid (or a dome cut flat at polar angle ``cut_angle``).

    Parameters
    ----------
    centre : (3,) float64 array
    radii : (3,) float64 array
        Semi-axes along the columns of ``frame``; the poles lie on the third.
    frame : (3, 3) float64 array
    spacing : float
        Wanted edge length.
    cut_angle : float
        Polar angle in [0, pi/2] below which the cap is removed and the cut
        closed with a flat disc (a helmet shape); 0 keeps the whole ellipsoid.

    Returns
    -------
    vertices : (n, 3) float64 array
    triangles : (t, 3) int64 array
    """
    radii = np.asarray(radii, dtype=np.float64)
    segments = ring_segments(max(radii[0], radii[1]), spacing)
    ring_count = max(3, segments // 2 - 1)
    if cut_angle > 0.0:
        theta = np.linspace(cut_angle, np.pi, ring_count + 1, endpoint=False)
    else:
        theta = np.pi * np.arange(1, ring_count + 1) / (ring_count + 1)
    local_z = -radii[2] * np.cos(theta)
    centres = centre + local_z[:, None] * frame[:, 2][None, :]
    ring_radii = np.column_stack([radii[0] * np.sin(theta), radii[1] * np.sin(theta)])
    tangents = np.repeat(frame[:, 2][None, :], len(theta), axis=0)
    normals = np.repeat(frame[:, 0][None, :], len(theta), axis=0)
    start = centres[0] if cut_angle > 0.0 else centre - radii[2] * frame[:, 2]
    vertices, triangles, _ = lathe(centres, tangents, normals, ring_radii, segments, start,
                                   centre + radii[2] * frame[:, 2])
    return vertices, triangles


def sphere_geometry(centre, radius: float, spacing: float):
    """Closed sphere: :func:`ellipsoid_geometry` with three equal semi-axes."""
    return ellipsoid_geometry(centre, np.full(3, radius), np.eye(3), spacing)


def prism_geometry(centre, half_length, radii, frame, segments, phase=0.0):
    """Closed prism along the frame's third axis with flat capped ends.

    ``radii`` (2,) are the semi-axes of its elliptical cross-section (of
    ``segments`` corners). Four segments with phase pi/4 give a box whose
    half extents are ``radii / sqrt(2)``.
    """
    axis = frame[:, 2]
    centres = np.stack([centre - half_length * axis, centre + half_length * axis])
    tangents = np.stack([axis, axis])
    normals = np.stack([frame[:, 0], frame[:, 0]])
    ring_radii = np.array([radii, radii], dtype=np.float64)
    vertices, triangles, _ = lathe(centres, tangents, normals, ring_radii, segments, centres[0], centres[1], phase)
    return vertices, triangles


def box_geometry(centre, half_extents, frame):
    """Closed box: ``half_extents`` (3,) along the columns of ``frame``."""
    half_extents = np.asarray(half_extents, dtype=np.float64)
    radii = np.sqrt(2.0) * half_extents[:2]
    return prism_geometry(np.asarray(centre, dtype=np.float64), half_extents[2], radii, frame, 4, np.pi / 4)


def cone_geometry(base_centre, radius, height, frame, spacing):
    """Closed cone from a base disc of ``radius`` to an apex ``height`` along
    the frame's third axis."""
    segments = ring_segments(radius, spacing)
    axis = frame[:, 2]
    centres = np.asarray(base_centre, dtype=np.float64)[None, :]
    vertices, triangles, _ = lathe(
        centres, axis[None, :], frame[:, 0][None, :], np.array([[radius, radius]]), segments, centres[0],
        centres[0] + height * axis
    )
    return vertices, triangles


def torus_geometry(centre, major_radii, minor_radius, frame, spacing):
    """Closed torus around the frame's third axis; the core is an ellipse
    with semi-axes ``major_radii`` (2,) along the first two frame axes."""
    major_radii = np.asarray(major_radii, dtype=np.float64)
    around = int(np.clip(np.ceil(2 * np.pi * major_radii.max() / spacing), MIN_TORUS_SEGMENTS, MAX_TORUS_SEGMENTS))
    tube = ring_segments(minor_radius, spacing)
    u = 2.0 * np.pi * np.arange(around) / around
    v = 2.0 * np.pi * np.arange(tube) / tube
    core = major_radii[0] * np.cos(u)[:, None] * frame[:, 0] + major_radii[1] * np.sin(u)[:, None] * frame[:, 1]
    outward = normalized(np.cos(u)[:, None] / major_radii[0] * frame[:, 0]
                         + np.sin(u)[:, None] / major_radii[1] * frame[:, 1])
    points = (
        centre
        + core[:, None, :]
        + minor_radius * np.cos(v)[None, :, None] * outward[:, None, :]
        + minor_radius * np.sin(v)[None, :, None] * frame[:, 2][None, None, :]
    )
    i = np.arange(around)[:, None]
    j = np.arange(tube)[None, :]
    a, b = i * tube + j, ((i + 1) % around) * tube + j
    c, d = ((i + 1) % around) * tube + (j + 1) % tube, i * tube + (j + 1) % tube
    triangles = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    vertices = points.reshape(-1, 3)
    if signed_volume(vertices, triangles) < 0:
        triangles = triangles[:, ::-1]
    return vertices, np.ascontiguousarray(triangles)


def grid_triangles(rows: int, columns: int) -> np.ndarray:
    """(2 (rows-1) (columns-1), 3) int64 triangles of an open rows x columns
    grid of vertices numbered row by row."""
    i = np.arange(rows - 1)[:, None]
    j = np.arange(columns - 1)[None, :]
    a, b = i * columns + j, i * columns + j + 1
    c, d = (i + 1) * columns + j + 1, (i + 1) * columns + j
    return np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3),
                           np.stack([a, c, d], -1).reshape(-1, 3)]).astype(np.int64)


def face_towards(vertices, triangles, direction) -> np.ndarray:
    """``triangles`` flipped if their summed normal points against ``direction``."""
    corners = vertices[triangles]
    normal_sum = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]).sum(axis=0)
    return np.ascontiguousarray(triangles[:, ::-1]) if np.dot(normal_sum, direction) < 0 else triangles


def signed_volume(vertices, triangles) -> float:
    """Volume enclosed by a closed surface; positive when it faces outward."""
    corners = vertices[triangles]
    return float(np.einsum("ij,ij->i", corners[:, 0], np.cross(corners[:, 1], corners[:, 2])).sum() / 6.0)
