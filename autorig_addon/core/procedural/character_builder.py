"""A character while it is being built: its rig, its parts, its random stream.

Each kind (:mod:`.kinds`) drives a :class:`CharacterBuilder`: it draws
numbers from the builder, adds bones to ``builder.rig``, scales the rig to
size (:meth:`~CharacterBuilder.fit_size`), mirrors the left side
(:meth:`~CharacterBuilder.settle`) and then grows parts around the bones:
tubes, rigid pieces, cloth. The queries about the body built so far
(:meth:`~CharacterBuilder.extent_along`, :meth:`~CharacterBuilder.band_ellipse`,
:meth:`~CharacterBuilder.drape`) let accessories and garments sit on it.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from ..geometry.bounding_box import bounding_box_diagonal
from .frames import Z, normalized
from .part_weights import closest_point_weights, stack_weight_blocks
from .parts import PART_BODY, PART_CLOTH, PART_RIGID, Part, mirrored_part
from .random_parameters import ACCESSORY_PROBABILITY, ROOT_BONE_PROBABILITY
from .rig_builder import RigBuilder
from .tubes import tube_part

#: Spacing of tube rings, as a fraction of the skeleton's bounding-box diagonal.
RING_SPACING_FRACTION = 1.0 / 55.0
#: Half-width of the zone where a tube vertex blends two bones, as a fraction
#: of the shorter bone; each character draws one value from this range.
JOINT_BLEND_RANGE = (0.15, 0.45)
#: Body vertices consulted per point when draping a sheet over the body.
DRAPE_NEIGHBOURS = 12


class CharacterBuilder:
    """A character under construction.

    Attributes
    ----------
    rng : numpy.random.Generator
        Every random number of the character comes from here, in a fixed order.
    rig : RigBuilder
    parts : list of Part
    size : float
        Bounding-box diagonal of the settled skeleton, metres.
    spacing : float
        Wanted edge length of the surfaces, metres.
    blend : float
        Half-width of the joint regions of the weights (:data:`JOINT_BLEND_RANGE`).
    """

    def __init__(self, rng: np.random.Generator):
        self.rng = rng
        self.rig = RigBuilder()
        self.parts: list = []
        self.size = 1.0
        self.spacing = 0.05
        self.blend = float(rng.uniform(*JOINT_BLEND_RANGE))

    # -- random draws -------------------------------------------------------
    def uniform(self, low, high) -> float:
        return float(self.rng.uniform(low, high))

    def integer(self, low, high) -> int:
        """An integer in [low, high)."""
        return int(self.rng.integers(low, high))

    def pick(self, options):
        """One of ``options``, each as likely."""
        return options[int(self.rng.integers(len(options)))]

    def chance(self, what: str) -> bool:
        """Whether the character gets the optional piece ``what`` (:data:`ACCESSORY_PROBABILITY`)."""
        return bool(self.rng.random() < ACCESSORY_PROBABILITY[what])

    # -- skeleton -----------------------------------------------------------
    def maybe_root(self) -> str | None:
        """A non-deforming ``root`` bone at the origin, with probability
        :data:`ROOT_BONE_PROBABILITY`; returns its name or None."""
        if self.rng.random() < ROOT_BONE_PROBABILITY:
            return self.rig.add("root", [0.0, 0.0, 0.0], [0.0, 0.3, 0.0], None, deform=False)
        return None

    def place_template(self, table, length_factor, lateral_factor=None, keep=None, root_parent=None):
        """Add a baked metarig (:mod:`.templates`) with each bone's length
        scaled by ``length_factor[name]`` (default 1). Bones connected in the
        template stay connected; other offsets scale with the parent's
        factor, and their x with ``lateral_factor[name]`` (shoulder and hip
        width). Only bones in ``keep`` (default all) are added; the template's
        roots get ``root_parent``."""
        lateral_factor = lateral_factor or {}
        template_heads, template_tails = {}, {}
        for name, parent, head, tail, deform in table:
            if keep is not None and name not in keep:
                continue
            head, tail = np.array(head), np.array(tail)
            template_heads[name], template_tails[name] = head, tail
            if parent is None:
                new_head = head.copy()
            elif np.allclose(head, template_tails[parent], atol=1e-4):
                new_head = self.rig.tail(parent).copy()
            else:
                offset = (head - template_heads[parent]) * length_factor.get(parent, 1.0)
                offset[0] *= lateral_factor.get(name, 1.0)
                new_head = self.rig.head(parent) + offset
            new_tail = new_head + (tail - head) * length_factor.get(name, 1.0)
            self.rig.add(name, new_head, new_tail, root_parent if parent is None else parent, deform)

    def fit_size(self, size: float, axis: int | None = 2) -> float:
        """Scale the rig so its extent along ``axis`` (None: largest extent)
        equals ``size``, put its lowest point on z = 0 and centre it on x = 0
        and y; returns the scale factor."""
        points = self.rig.points()
        extent = points.max(0) - points.min(0)
        scale = size / (extent.max() if axis is None else extent[axis])
        low = points.min(0) * scale
        high = points.max(0) * scale
        shift = np.array([0.0, -0.5 * (low[1] + high[1]), -low[2]])
        self.rig.transform_all(lambda p: p * scale + shift)
        return scale

    def settle(self):
        """Mirror the left side and fix the mesh resolution from the rig size."""
        self.rig.symmetrize()
        self.size = bounding_box_diagonal(self.rig.points())
        self.spacing = self.size * RING_SPACING_FRACTION

    # -- parts --------------------------------------------------------------
    def add_part(self, part: Part, mirror: bool = False):
        """Add ``part``, and its mirror twin across x = 0 when ``mirror``."""
        self.parts.append(part)
        if mirror:
            self.parts.append(mirrored_part(part))

    def tube(self, name, bones, radii, up=Z, part_type=PART_BODY, parent="auto", child=None, mirror=False, bulge=None):
        """A closed shell around the path of ``bones`` (:func:`.tubes.tube_part`).

        ``parent`` is the bone the first bone blends into at the path start
        ("auto": its nearest deforming ancestor; None: none). Returns the part.
        """
        first_parent = self.rig.deforming_parent(bones[0]) if parent == "auto" else parent
        part = tube_part(name, self.rig.path_points(bones), bones, radii, up, self.spacing, self.blend, part_type,
                         first_parent, child, bulge)
        self.add_part(part, mirror)
        return part

    def rigid(self, name, geometry, bone, part_type=PART_RIGID, mirror=False):
        """A closed piece moved only by ``bone``; ``geometry`` is (vertices, triangles)."""
        vertices, triangles = geometry
        part = Part(name, part_type, True, vertices, triangles, (bone,), np.ones((len(vertices), 1)))
        self.add_part(part, mirror)
        return part

    def cloth(self, name, vertices, triangles, body=None):
        """An open shell weighted by the body's weights at its closest point
        on the body shells (those called ``body``, if given)."""
        body_vertices, body_triangles, names, body_weights = self.body_surface(body)
        weights = closest_point_weights(vertices, body_vertices, body_triangles, body_weights)
        used = np.flatnonzero(weights.max(axis=0) > 0)
        self.add_part(Part(name, PART_CLOTH, False, vertices, triangles, tuple(names[k] for k in used),
                           weights[:, used]))

    # -- the body built so far ----------------------------------------------
    def body_surface(self, names=None):
        """Vertices, triangles, bone names and (n, bones) weights of the
        closed body shells so far (only those called ``names``, if given)."""
        body = [p for p in self.parts if p.part_type == PART_BODY and p.closed and (names is None or p.name in names)]
        if not body:
            raise ValueError("no body shells yet")
        offsets = np.cumsum([0] + [len(p.vertices) for p in body])
        names, weights = stack_weight_blocks([(p.bone_names, p.weights) for p in body])
        vertices = np.concatenate([p.vertices for p in body])
        triangles = np.concatenate([p.triangles + o for p, o in zip(body, offsets)])
        return vertices, triangles, names, weights

    def extent_along(self, origin, direction, reach, body=None) -> float:
        """How far the body surface lies from ``origin`` along ``direction``,
        using body vertices within ``reach`` of that ray (0 for none)."""
        vertices = self.body_surface(body)[0]
        direction = normalized(direction)
        relative = vertices - origin
        along = relative @ direction
        across = np.linalg.norm(relative - along[:, None] * direction, axis=1)
        near = (across < reach) & (along > 0)
        return float(along[near].max()) if near.any() else 0.0

    def band_ellipse(self, height, thickness, centre_xy, body=None):
        """(2,) semi-axes (x, y) of the smallest ellipse around ``centre_xy``,
        with the aspect of the band's bounding box, that encloses the body
        vertices whose z lies within ``thickness`` of ``height``."""
        vertices = self.body_surface(body)[0]
        band = vertices[np.abs(vertices[:, 2] - height) < thickness][:, :2] - centre_xy
        if len(band) == 0:
            return np.array([self.spacing, self.spacing])
        half = np.maximum(np.abs(band).max(axis=0), 1e-6)
        scale = np.sqrt(((band / half) ** 2).sum(axis=1).max())
        return half * scale

    def drape(self, grid_2d, plane_axes, normal_axis, gap, body=None):
        """Height over the body of each 2-D grid point: the farthest body
        vertex along ``normal_axis`` among the :data:`DRAPE_NEIGHBOURS`
        nearest in the plane, plus ``gap``."""
        vertices = self.body_surface(body)[0]
        tree = cKDTree(vertices[:, plane_axes])
        _, nearest = tree.query(grid_2d.reshape(-1, 2), k=DRAPE_NEIGHBOURS)
        return vertices[nearest, normal_axis].max(axis=1).reshape(grid_2d.shape[:-1]) + gap
