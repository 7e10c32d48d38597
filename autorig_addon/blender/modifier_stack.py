"""Where posing acts in a mesh's modifier stack: the place of the Armature
modifier, and the rest shape it deforms there.

A mesh's modifiers may shape the character before any armature moves it: a
Mirror modifier completing a half-modelled body, a Simple Deform, Lattice
or Displace bending it into the shape the user sees. Bones fitted to that
shape only pose it when the Armature modifier comes *after* those
modifiers. This add-on used to put it first: posing moved the undeformed
shape, which they then bent again (a 30 degree turn of a twisted arm moved
it a fraction of the way), and only the modelled half of a mirrored body
was read, each pose of it copied onto the other side. Modifiers that
finish the surface (Subdivision Surface, Corrective Smooth, Solidify,
Triangulate, ...) and those whose output is not the mesh's own vertices
(Array, Boolean, Remesh, ...) come after it, as in Blender's own rigs: the
rig fits the shape before them (the cage).

The rule (:func:`armature_place`): the Armature modifier goes right after
the last of the stack's leading run of rest-shape modifiers
(:data:`REST_SHAPE_TYPES`; modifiers that move no vertex,
:data:`SHAPELESS_TYPES`, may sit inside the run). An Armature modifier the
user already has keeps its place (:func:`binding_place`; Blender's Ctrl+P
appends it to the stack). The shape it deforms is read with every modifier
from its place on switched off (:func:`stack_cut`).

The modifiers before it may add vertices: a Mirror, or a Subdivision
Surface the user put before their own Armature modifier. Blender keeps the
mesh's own vertices first, in their order, and appends the new ones (a
Mirror's merged copies left out), in Blender 4.2 to 5.0 alike;
:func:`own_vertices_first` checks it on every read. The weights are then
computed on the whole shape and written on the mesh's own vertices; the
modifiers hand them on to the vertices they add (a Mirror with ``.L`` and
``.R`` groups swapped), which the skin job checks once written.
"""

from __future__ import annotations

from contextlib import contextmanager

import bpy
import numpy as np

#: Modifiers that move vertices without adding or removing any: part of the
#: rest shape when they come before the Armature modifier.
DEFORM_ONLY_TYPES = frozenset({
    "CAST", "CURVE", "DISPLACE", "HOOK", "LAPLACIANDEFORM", "LAPLACIANSMOOTH", "LATTICE", "MESH_DEFORM",
    "SHRINKWRAP", "SIMPLE_DEFORM", "SMOOTH", "SURFACE_DEFORM", "WARP", "WAVE",
})
#: Modifiers that shape the rest pose the Armature modifier deforms: the deform-only ones and Mirror,
#: whose added vertices map back to the mesh's own (:func:`own_vertices_first`).
REST_SHAPE_TYPES = DEFORM_ONLY_TYPES | {"MIRROR"}
#: Modifiers that move no vertex: the Armature modifier may sit before or after them (an
#: Armature modifier at rest moves nothing either).
SHAPELESS_TYPES = frozenset({
    "ARMATURE", "DATA_TRANSFER", "NORMAL_EDIT", "UV_PROJECT", "UV_WARP", "VERTEX_WEIGHT_EDIT",
    "VERTEX_WEIGHT_MIX", "VERTEX_WEIGHT_PROXIMITY", "WEIGHTED_NORMAL",
})
#: Modifiers that only refine the surface the rig is fitted to: rigging the
#: shape before them (the cage) is the usual order, so prediction never
#: compares the shape before them with the one the user sees.
SURFACE_FINISH_TYPES = frozenset({"SUBSURF", "MULTIRES", "CORRECTIVE_SMOOTH", "TRIANGULATE", "EDGE_SPLIT"})
#: Name of the temporary point attribute that numbers a mesh's own vertices while it is read.
_OWN_INDEX_ATTRIBUTE = "autorig_own_vertex"


def armature_place(obj) -> int:
    """Index in ``obj.modifiers`` where a new Armature modifier goes: right
    after the last rest-shape modifier of the stack's leading run
    (:data:`REST_SHAPE_TYPES`, with :data:`SHAPELESS_TYPES` allowed in
    between), 0 when the stack starts with anything else.

    Visibility does not matter: a modifier switched off keeps its place
    for when it is switched on.
    """
    place = 0
    for index, modifier in enumerate(obj.modifiers):
        if modifier.type in REST_SHAPE_TYPES:
            place = index + 1
        elif modifier.type not in SHAPELESS_TYPES:
            break
    return place


def kept_armature_modifier(obj, armature=None):
    """The Armature modifier of ``obj`` a binding to ``armature`` reuses: one
    on that armature first, then an empty one, then one on another armature
    (retargeted); None when ``obj`` has none. ``armature`` None: a new
    armature, which none is on yet."""
    modifiers = [modifier for modifier in obj.modifiers if modifier.type == "ARMATURE"]
    if not modifiers:
        return None
    return min(modifiers, key=lambda modifier: (armature is None or modifier.object != armature,
                                                modifier.object is not None))


def binding_place(obj, armature=None) -> int:
    """Where posing by ``armature`` acts on ``obj``: the place of the Armature
    modifier the binding reuses (the user put it there), else
    :func:`armature_place`."""
    kept = kept_armature_modifier(obj, armature)
    return list(obj.modifiers).index(kept) if kept is not None else armature_place(obj)


def cut_off(obj, place: int) -> list:
    """The modifiers from ``place`` on that the viewport evaluates (switched on)."""
    return [modifier for modifier in list(obj.modifiers)[place:] if modifier.show_viewport]


def vertex_adders(obj, place: int) -> list:
    """The modifiers switched on before ``place`` that may add or remove
    vertices (a Mirror; a Subdivision Surface before the user's own Armature modifier)."""
    return [modifier for modifier in list(obj.modifiers)[:place]
            if modifier.show_viewport and modifier.type not in DEFORM_ONLY_TYPES | SHAPELESS_TYPES]


@contextmanager
def stack_cut(places: dict):
    """Switch off, in the viewport, every modifier of each object from its
    place on (``places``: object -> index) while the block runs, so the
    evaluated depsgraph holds the shape the Armature modifier deforms there;
    each modifier's own setting comes back afterwards. The view layer is
    updated on entering and leaving when anything was switched off."""
    switched = [modifier for obj, place in places.items() for modifier in cut_off(obj, place)]
    for modifier in switched:
        modifier.show_viewport = False
    try:
        if switched:
            bpy.context.view_layer.update()
        yield
    finally:
        for modifier in switched:
            modifier.show_viewport = True
        if switched:
            bpy.context.view_layer.update()


@contextmanager
def numbered_own_vertices(meshes):
    """Number the vertices of each mesh datablock in a temporary integer point
    attribute while the block runs (always removed), so the rows of an
    evaluated mesh can be traced back (:func:`own_vertices_first`)."""
    numbered = []
    try:
        for mesh in dict.fromkeys(meshes):
            stale = mesh.attributes.get(_OWN_INDEX_ATTRIBUTE)  # left by a crash: Blender would rename a new one
            if stale is not None:
                mesh.attributes.remove(stale)
            attribute = mesh.attributes.new(_OWN_INDEX_ATTRIBUTE, "INT", "POINT")
            numbered.append(mesh)
            attribute.data.foreach_set("value", np.arange(len(mesh.vertices), dtype=np.int32))
        if numbered:
            bpy.context.view_layer.update()
        yield
    finally:
        for mesh in numbered:
            attribute = mesh.attributes.get(_OWN_INDEX_ATTRIBUTE)
            if attribute is not None:
                mesh.attributes.remove(attribute)
        if numbered:
            bpy.context.view_layer.update()


def own_vertices_first(evaluated_mesh, own_count: int) -> bool:
    """Whether the first ``own_count`` vertices of an evaluated mesh read
    inside :func:`numbered_own_vertices` are the mesh's own vertices, in
    their order: the rule weights are written back by (False when a
    Mirror's Bisect cut the mesh)."""
    attribute = evaluated_mesh.attributes.get(_OWN_INDEX_ATTRIBUTE)
    if attribute is None or len(evaluated_mesh.vertices) < own_count:
        return False
    rows = np.empty(len(evaluated_mesh.vertices), dtype=np.int32)
    attribute.data.foreach_get("value", rows)
    return bool(np.array_equal(rows[:own_count], np.arange(own_count)))
