"""What an object is to a weighting run, besides a mesh to weight.

- **Helpers the user never made to be seen**: bone custom shapes (the glTF
  importer's ``Icosphere``), objects hidden from render, objects in no
  rendered collection of the scene. A run never picks them by itself
  (:func:`without_helpers`); named explicitly, they are weighted like any mesh.
- **Props parented to a bone** (KayKit helmets, swords, shields, capes;
  :func:`.armature_binding.bone_parent`): already rigged, rigidly. Picked
  by a run itself they are left as they are;
  named or selected, they are bound wholly to that bone and the bone parent
  is replaced by the armature (:class:`RigidBinding`), keeping their rest
  position, so posing moves them exactly as before. A mesh is never both
  deformed by an Armature modifier and carried by a bone.
- **Props held as objects of their own** (a sword, a shield, a mug; told
  from the body by Auto-Rig, ``core.rigging.props``): bound wholly to the
  bone nearest to where they are held (:func:`held_binding`).
- **Linked duplicates** (Alt+D: two gloves sharing one mesh): weights live
  in the mesh, so each object written gets a mesh of its own first
  (:func:`give_own_mesh`), or the second glove would overwrite the first's.
"""

from __future__ import annotations

from dataclasses import dataclass

import bpy
from mathutils import Matrix

from ..core.errors import InputError
from ..core.messages import listed_names
from ..core.rigging.props import held_note, holding_bone
from ..core.types import Skeleton
from .armature_binding import bone_parent, objects_at_rest
from .convert import deform_bone_names


@dataclass(frozen=True)
class RigidBinding:
    """A prop to be bound wholly to one bone: the bone it was parented to,
    or the one holding it (``held``).

    Attributes
    ----------
    obj : bpy.types.Object, the mesh
    armature : bpy.types.Object, the armature its bone belongs to
    bone : str, the bone's name (a deform bone)
    rest_world : mathutils.Matrix, the object's world matrix with the armature
        in its rest position: where the Armature modifier must start from
    held : bool, a prop told from the body (``core.rigging.props``), not parented to the bone
    """

    obj: object
    armature: object
    bone: str
    rest_world: Matrix
    held: bool = False

    @property
    def note(self) -> str:
        """What the report says about the object (after its name)."""
        if self.held:
            return held_note(self.bone)
        return f"bound wholly to bone '{self.bone}' (it was parented to that bone)"


def left_rigid_note(obj) -> str:
    """What the report says (after the object's name) about a bone-parented
    prop a run leaves as it is."""
    return f"left rigid, parented to bone '{bone_parent(obj)}'"


def rigid_binding(obj, armature) -> RigidBinding | None:
    """How to bind the bone-parented ``obj`` to ``armature``, or None when
    ``obj`` has no bone parent or its bone does not deform (it then stays
    rigid on its bone: binding it to a bone the Armature modifier ignores
    would leave it behind).

    Raises
    ------
    InputError when the bone belongs to another armature.
    """
    bone = bone_parent(obj)
    if bone is None:
        return None
    if obj.parent != armature:
        raise InputError(
            f"'{obj.name}' is parented to bone '{bone}' of '{obj.parent.name}', not of '{armature.name}': "
            f"clear its parent (Alt+P > Clear and Keep Transformation) to weight it to '{armature.name}'."
        )
    if bone not in deform_bone_names(armature):
        return None
    with objects_at_rest([obj]):
        rest_world = obj.matrix_world.copy()
    return RigidBinding(obj, armature, bone, rest_world)


def held_binding(obj, armature, grip, skeleton: Skeleton) -> RigidBinding:
    """How to bind ``obj``, a prop the character holds (``core.rigging.props``),
    to ``armature``: wholly to the deform bone of ``skeleton`` (the
    armature's, world space) nearest to its ``grip`` (3,), from where it
    stands now."""
    with objects_at_rest([obj]):
        rest_world = obj.matrix_world.copy()
    return RigidBinding(obj, armature, holding_bone(grip, skeleton), rest_world, held=True)


def carried_on_bones(objects: list) -> dict:
    """The objects of ``objects`` an armature carries on one bone (parented
    to it, no Armature modifier) while it deforms another of ``objects``:
    the props of the artist's own rig (KayKit's weapons on their hand slots),
    each mapped to the middle of its bone at rest, world space (a hand slot
    lies in the palm; a hand bone's middle is in the hand, where its head, at
    the wrist, may lie as near the new forearm). A rig made of parts on bones
    alone (a robot) deforms none of them and carries no props."""
    import numpy as np

    deforming = {modifier.object for obj in objects for modifier in obj.modifiers
                 if modifier.type == "ARMATURE" and modifier.object is not None}
    carried = {}
    for obj in objects:
        bone = bone_parent(obj)
        if bone is None or obj.parent not in deforming or bone not in obj.parent.data.bones or \
                any(modifier.type == "ARMATURE" for modifier in obj.modifiers):
            continue
        rest_bone = obj.parent.data.bones[bone]
        middle = obj.parent.matrix_world @ ((rest_bone.head_local + rest_bone.tail_local) / 2.0)
        carried[obj] = np.array(middle, dtype=np.float64)
    return carried


def split_bone_parented(objects: list, armature, named: bool) -> tuple[list, list, list]:
    """Split ``objects`` into (plain meshes, rigid bindings, props left rigid).

    Props on a bone are bound wholly to it (:func:`rigid_binding`) when
    ``named`` (the user named or selected them); props a run picked itself,
    and props on a bone that does not deform, are left as they are.
    """
    plain, rigid, left = [], [], []
    for obj in objects:
        if bone_parent(obj) is None:
            plain.append(obj)
            continue
        binding = rigid_binding(obj, armature) if named else None
        if binding is None:
            left.append(obj)
        else:
            rigid.append(binding)
    return plain, rigid, left


def custom_shape_objects() -> set:
    """Objects any armature of the file displays its bones with."""
    return {
        pose_bone.custom_shape
        for obj in bpy.data.objects if obj.type == "ARMATURE" and obj.pose is not None
        for pose_bone in obj.pose.bones if pose_bone.custom_shape is not None
    }


def _rendered_collections(scene) -> set:
    """The scene's collections whose objects render: its master collection and
    the children reached through collections not hidden from render."""
    rendered, pending = {scene.collection}, [scene.collection]
    while pending:
        for child in pending.pop().children:
            if not child.hide_render and child not in rendered:
                rendered.add(child)
                pending.append(child)
    return rendered


def without_helpers(objects: list, context=None) -> list:
    """``objects`` without the helpers of ``context``'s scene (default: the
    current context): bone shapes, objects hidden from render and objects
    outside the view layer or in no rendered collection."""
    context = context or bpy.context
    shapes = custom_shape_objects()
    rendered = _rendered_collections(context.scene)
    in_view_layer = set(context.view_layer.objects)
    return [
        obj for obj in objects
        if obj not in shapes and not obj.hide_render and obj in in_view_layer and set(obj.users_collection) & rendered
    ]


def mesh_sharers(obj) -> list:
    """Other objects using ``obj``'s mesh datablock (linked duplicates)."""
    return [other for other in bpy.data.objects if other != obj and other.data is not None and other.data == obj.data]


def shared_mesh_notes(objects: list) -> dict:
    """What the report says (after the object's name) about the linked
    duplicates among ``objects``, as {object: note}.

    ``objects`` are written in this order, and each gets a copy of its mesh
    (:func:`give_own_mesh`) when another object still uses that mesh at its
    turn: the last of a group written together keeps the original, by then
    its own, and gets no note."""
    notes, written = {}, set()
    for obj in objects:
        sharers = [other for other in mesh_sharers(obj) if other not in written]
        written.add(obj)
        if sharers:
            names = listed_names([other.name for other in sharers], quoted=True)
            notes[obj] = (f"shared its mesh '{obj.data.name}' with {names}: it now has its own copy, "
                          "so each keeps its own weights")
    return notes


def give_own_mesh(obj) -> None:
    """Give ``obj`` a copy of its mesh when another object uses the same one;
    :class:`~.snapshot.ObjectSnapshot` puts the shared mesh back on failure."""
    if mesh_sharers(obj):
        obj.data = obj.data.copy()
