"""Procedural rigged characters: a skeleton, a surface and skin weights from one seed.

:func:`generate_character` draws a skeleton morphology (biped, quadruped,
many-legged, winged, tailed, long chain, fish or prop), grows a body around
it and derives the weights from how each piece was built:

* **Body shells** are generalised cylinders (elliptical rings of varying
  radius, rounded end caps) around chains of bones, plus ellipsoids for heads.
  A ring's vertices take the bone the ring lies on, blended
  linearly with the neighbouring bone inside a joint region. Shells overlap
  and intersect where limbs meet the torso, as many game characters are
  built; each shell on its own is closed, watertight and outward facing.
* **Rigid accessories** (eyes, helmets, swords, buttons, horns, feathers,
  prop pieces) follow exactly one bone.
* **Clothing shells** (skirt, cape, blanket) are open surfaces offset from the
  body. Either they take the body's weights at the closest body point, or
  they get their own bones placed outside the body and weights that follow
  those bones.
* **Parts driven by bones outside the body**: skirt and cape bones, hair
  chains, an anglerfish lure, a sword on a floating weapon bone.

Everything is drawn from ``numpy.random.default_rng(seed)`` in a fixed order,
so a seed always gives the same arrays. No bpy: the Blender layer converts
the result to objects.

Conventions: metres, z up, characters face -y, left side (``.L``) at +x.
Symmetric kinds are built on the left and mirrored across x = 0, so ``.L``
and ``.R`` joints mirror each other exactly.

Where things are:

* :mod:`.character`: :func:`generate_character`, :class:`ProceduralCharacter`,
  :data:`KINDS`.
* :mod:`.kinds`: one module per kind (biped, quadruped, dragon, winged,
  multileg, tailed, long_chain, fish, prop) and :data:`.kinds.BUILDERS`.
* :mod:`.character_builder`: the character under construction (random
  draws, parts, queries about the body built so far);
  :mod:`.rig_builder`: its bones; :mod:`.parts`: its pieces and part types.
* :mod:`.tubes` (body shells), :mod:`.heads`, :mod:`.accessories`,
  :mod:`.cloth` (garments): what is grown around the bones.
* :mod:`.part_weights`: weights along chains, at the closest body point,
  and the combination of per-part weight blocks.
* :mod:`.shapes` (primitive surfaces), :mod:`.frames` (directions,
  rotations, frames), :mod:`.polylines` (arc length): geometry helpers.
* :mod:`.random_parameters` (sizes and accessory chances),
  :mod:`.templates` (Rigify metarigs baked to tables).
"""

from .character import KINDS, ProceduralCharacter, generate_character, generate_characters
from .parts import PART_BODY, PART_CLOTH, PART_DRIVEN, PART_RIGID, PART_TYPES

__all__ = [
    "KINDS",
    "PART_BODY",
    "PART_CLOTH",
    "PART_DRIVEN",
    "PART_RIGID",
    "PART_TYPES",
    "ProceduralCharacter",
    "generate_character",
    "generate_characters",
]
