"""Fish: the Rigify shark as a shark, a deep-bodied reef fish or a dolphin
(flukes instead of a tail fin), with an analytic body outline."""

from __future__ import annotations

import numpy as np

from ...geometry.segments import polyline_arc_lengths
from ...skeleton.naming import chain_names
from .. import templates
from ..frames import Y, Z, normalized
from ..parts import PART_DRIVEN
from ..polylines import points_at_fractions, segment_lengths
from ..random_parameters import SIZE_RANGE
from ..shapes import sphere_geometry
from ..tubes import round_radii, scaled_radii

FISH_VARIANTS = ("shark", "reef_fish", "dolphin")
#: Bones of the body from snout to tail, through the root in the middle.
FISH_BODY_PATH = ("spine.007", "spine.006", "spine.005", "spine.004", "spine.008", "spine.003", "spine.002",
                  "spine.001", "spine")
#: Body half-height over body length, and width over height, per variant.
FISH_DEPTH = {"shark": (0.06, 0.09), "reef_fish": (0.15, 0.25), "dolphin": (0.07, 0.1)}
FISH_ASPECT = {"shark": (0.7, 0.9), "reef_fish": (0.3, 0.5), "dolphin": (0.8, 1.0)}
#: Body outline p^a (1 - p)^b along the length p (0 snout, 1 tail), and its
#: smallest value at the snout and at the tail, as fractions of the peak.
FISH_PROFILE_EXPONENTS = (0.45, 0.9)
FISH_PROFILE_FLOOR = (0.15, 0.1)
#: Fin lengths relative to the Rigify shark's; reef fish fins are longer.
FISH_FIN_SIZE = (0.5, 1.1)
FISH_TAIL_FIN_SIZE = (0.6, 1.3)
REEF_FISH_FIN_BOOST = 1.3
#: How deep inside the body fin roots sit, as a fraction of the local radius.
FISH_FIN_ROOT_DEPTH = 0.7
#: Fin shells: part name, bones, (chord, thickness) in template metres at each joint.
FISH_FINS = (
    ("top_fin", ("top_fin", "top_fin.001"), ((0.16, 0.02), (0.08, 0.012), (0.02, 0.006))),
    ("side_fin.L", ("shoulder.L", "side_fin.L", "side_fin.001.L"),
     ((0.1, 0.03), (0.14, 0.025), (0.1, 0.015), (0.03, 0.008))),
    ("chest_fin.L", ("chest_fin.Bot.L",), ((0.06, 0.012), (0.02, 0.006))),
    ("mid_fin_top", ("mid_fin.Top",), ((0.06, 0.012), (0.02, 0.006))),
    ("mid_fin_bottom", ("mid_fin.Bot",), ((0.06, 0.012), (0.02, 0.006))),
    ("tail_fin_top", ("back_fin.T.Bk", "back_fin.T.001.Bk", "back_fin.T.002.Bk"),
     ((0.12, 0.02), (0.09, 0.015), (0.06, 0.01), (0.015, 0.005))),
    ("tail_fin_bottom", ("back_fin.B.Bk", "back_fin.B.001.Bk"), ((0.1, 0.02), (0.06, 0.012), (0.015, 0.005))),
    ("fluke.L", ("fluke.L", "fluke.001.L"), ((0.14, 0.02), (0.1, 0.015), (0.03, 0.006))),
)
FISH_JAW_RADII = ((0.05, 0.09), (0.04, 0.07), (0.02, 0.03))  # (height, width)
#: Bones whose subtree is moved so their head sits just inside the body surface.
FISH_FIN_ROOTS = ("top_fin", "shoulder.L", "chest_fin.Bot.L", "mid_fin.Top", "mid_fin.Bot", "back_fin.T.Bk",
                  "back_fin.B.Bk", "jaw.master")


class _FishBody:
    """The analytic outline of a fish body around its spine path (k + 1, 3)."""

    def __init__(self, path, half_height, aspect):
        self.path = path
        self.length = float(segment_lengths(path).sum())
        self.half_height = half_height
        self.aspect = aspect

    def radii(self, fraction):
        """(r, 2) semi-axes (height, width) at path ``fraction`` (r,)."""
        a, b = FISH_PROFILE_EXPONENTS
        peak = (a / (a + b)) ** a * (b / (a + b)) ** b
        fraction = np.clip(np.asarray(fraction, dtype=np.float64), 0.0, 1.0)
        shape = fraction ** a * (1.0 - fraction) ** b / peak
        height = self.half_height * np.maximum(shape, np.interp(fraction, [0.0, 1.0], FISH_PROFILE_FLOOR))
        return np.column_stack([height, self.aspect * height])

    def surface(self, point, direction=None):
        """Centre, unit radial direction and radius of the body surface seen
        from the spine point nearest ``point`` (towards ``point``, or along
        ``direction`` when given)."""
        fraction = polyline_arc_lengths(point[None], self.path)[0] / self.length
        centre = points_at_fractions(self.path, np.array([fraction]))[0]
        step = 1e-3
        ahead = points_at_fractions(self.path, np.clip(np.array([fraction - step, fraction + step]), 0, 1))
        tangent = normalized(ahead[1] - ahead[0])
        radial = (point - centre) if direction is None else np.asarray(direction, dtype=np.float64)
        radial = radial - np.dot(radial, tangent) * tangent
        radial = normalized(radial) if np.linalg.norm(radial) > 1e-9 else normalized(Z - np.dot(Z, tangent) * tangent)
        normal = normalized(Z - np.dot(Z, tangent) * tangent)
        binormal = np.cross(tangent, normal)
        height, width = self.radii(np.array([fraction]))[0]
        radius = 1.0 / np.sqrt((np.dot(radial, normal) / height) ** 2 + (np.dot(radial, binormal) / width) ** 2)
        return centre, radial, radius


def build_fish(ch) -> str:
    """A shark, reef fish or dolphin; returns the variant."""
    rig = ch.rig
    variant = ch.pick(FISH_VARIANTS)
    fins, tail_fins, thick = ch.uniform(*FISH_FIN_SIZE), ch.uniform(*FISH_TAIL_FIN_SIZE), ch.uniform(0.8, 1.3)
    if variant == "reef_fish":
        fins *= REEF_FISH_FIN_BOOST
    fin_bones = {"top_fin", "top_fin.001", "shoulder.L", "side_fin.L", "side_fin.001.L", "chest_fin.Bot.L",
                 "mid_fin.Top", "mid_fin.Bot"}
    tail_bones = {"back_fin.T.Bk", "back_fin.T.001.Bk", "back_fin.T.002.Bk", "back_fin.B.Bk", "back_fin.B.001.Bk"}
    lengths = {**{b: fins for b in fin_bones}, **{b: tail_fins for b in tail_bones}}
    keep = {row[0] for row in templates.SHARK}
    if variant == "dolphin":
        keep -= tail_bones | {"mid_fin.Top", "mid_fin.Bot", "chest_fin.Bot.L"}
    root = ch.maybe_root()
    ch.place_template(templates.SHARK, lengths, None, keep, root)
    rig.set_tail("shoulder.L", rig.head("side_fin.L"))
    if variant == "dolphin":
        start = rig.tail("spine") - 0.3 * rig.length("spine") * rig.direction("spine")
        span = 0.35 * tail_fins
        rig.add_chain(["fluke.L", "fluke.001.L"], start, [normalized([1.0, 0.6, 0.0]), normalized([1.0, 1.2, 0.0])],
                      [0.55 * span, 0.45 * span], "spine")
    body_length = segment_lengths(rig.path_points(FISH_BODY_PATH)).sum()
    body = _FishBody(rig.path_points(FISH_BODY_PATH), ch.uniform(*FISH_DEPTH[variant]) * body_length,
                     ch.uniform(*FISH_ASPECT[variant]))
    for bone in FISH_FIN_ROOTS:
        if rig.has(bone):
            centre, radial, radius = body.surface(rig.head(bone))
            rig.translate_subtree(bone, centre + FISH_FIN_ROOT_DEPTH * radius * radial - rig.head(bone))
    lure = []
    if ch.chance("lure"):
        centre, radial, radius = body.surface(body.path[0] + 0.12 * (body.path[-1] - body.path[0]), Z)
        start = centre + 0.8 * radius * radial
        length = ch.uniform(0.15, 0.35) * body.length
        lure = rig.add_chain(chain_names("lure", 2), start,
                             [normalized([0.0, -0.4, 1.0]), normalized([0.0, -1.0, -0.2])],
                             [0.5 * length, 0.5 * length], "spine.007")
    unit = ch.fit_size(ch.uniform(*SIZE_RANGE["fish"]), axis=1)
    ch.settle()
    body = _FishBody(rig.path_points(FISH_BODY_PATH), body.half_height * unit, body.aspect)
    ch.tube("body", list(FISH_BODY_PATH), body.radii, up=Z, parent=None)
    for name, bones, radii in FISH_FINS:
        if all(rig.has(b) for b in bones):
            scale = thick * unit * (tail_fins if bones[0] in tail_bones or name == "fluke.L" else fins)
            ch.tube(name, list(bones), scaled_radii(radii, scale), up=Y, mirror=name.endswith(".L"))
    ch.tube("jaw", ["jaw", "jaw.001"], scaled_radii(FISH_JAW_RADII, thick * unit), up=Z)
    # Eyes on the head surface, each moved by its eye bone.
    centre, radial, radius = body.surface(rig.head("eye.L"), normalized([1.0, 0.0, 0.6]))
    eye_radius = ch.uniform(0.12, 0.25) * radius
    eye_centre = centre + (radius - 0.4 * eye_radius) * radial
    rig.place("eye.L", eye_centre, eye_centre + 2.0 * eye_radius * radial)
    ch.rigid("eye.L", sphere_geometry(eye_centre, eye_radius, ch.spacing), "eye.L", mirror=True)
    if lure:
        r = 0.02 * body.half_height
        ch.tube("lure", lure, round_radii([1.0, 0.8, 0.6], r), up=Y, part_type=PART_DRIVEN)
        light = 0.12 * body.half_height
        ch.rigid("lure_light", sphere_geometry(rig.tail(lure[-1]), light, ch.spacing), lure[-1])
    return variant
