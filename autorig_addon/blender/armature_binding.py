"""How meshes follow armatures: which armature a mesh is bound to, showing
armatures at rest, unbinding a mesh and removing an armature.

One rule, :func:`armature_bindings`, says every way a mesh follows an
armature, in the order Blender applies them:

1. each Armature modifier on an armature: the armature **deforms** it;
2. its parent, when that is an armature: parent type *Armature* deforms it
   (Blender's old binding), parent type *Bone* **carries** it rigidly on
   that bone (a prop: a helmet, a sword), parent type *Object* carries it
   whole, like any child.

Every question the jobs ask is read off that list:

- :func:`bound_armature`: the armature a mesh is bound to, the first of
  the list (a transfer's source, a mesh Auto-Rig would re-bind, a mesh
  bound to a predicted armature);
- :func:`deforms`: whether an armature moves a mesh vertex by vertex (the
  skinned meshes of a rigged file, ``characters``);
- :func:`bone_parent`: the bone carrying a prop (``object_roles``);
- :func:`is_unbound`: a mesh a run may weight when none is named: bound to
  no armature, or a prop on a bone (the run then leaves it rigid);
- :func:`posing_armatures`: the armatures whose pose moves a mesh (the
  ones put at rest while it is read);
- :func:`followers`: every object an armature's bones move (what a
  rebuilt or removed armature would leave behind or displace).

Nothing here writes weights: binding a mesh is :mod:`.weight_writer`'s.
"""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass

import bpy

from ..core.errors import InputError


@dataclass(frozen=True)
class ArmatureBinding:
    """One way a mesh follows an armature.

    Attributes
    ----------
    armature : bpy.types.Object of type 'ARMATURE'
    deforms : bool, the armature moves the mesh vertex by vertex (an
        Armature modifier, or the *Armature* parent type); otherwise it
        carries the mesh rigidly
    bone : str or None, the bone carrying the mesh (parent type *Bone*)
    """

    armature: object
    deforms: bool
    bone: str | None = None


def armature_bindings(obj) -> list[ArmatureBinding]:
    """Every way ``obj`` follows an armature, in the order Blender applies
    them: its Armature modifiers on an armature, then its armature parent
    (see the module docstring). Empty for a mesh that follows none."""
    bindings = [ArmatureBinding(modifier.object, True) for modifier in obj.modifiers
                if modifier.type == "ARMATURE" and modifier.object is not None and modifier.object.type == "ARMATURE"]
    parent = obj.parent
    if parent is not None and parent.type == "ARMATURE":
        bone = obj.parent_bone if obj.parent_type == "BONE" and obj.parent_bone else None
        bindings.append(ArmatureBinding(parent, obj.parent_type == "ARMATURE", bone))
    return bindings


def bound_armature(obj):
    """The armature ``obj`` is bound to (the first of :func:`armature_bindings`), or None."""
    bindings = armature_bindings(obj)
    return bindings[0].armature if bindings else None


def find_armature(obj):
    """:func:`bound_armature`, refusing a mesh bound to none.

    Raises
    ------
    InputError when there is none.
    """
    armature = bound_armature(obj)
    if armature is None:
        raise InputError(
            f"'{obj.name}' is not bound to an armature: give it an Armature modifier "
            "or parent it to the armature (Ctrl+P > With Empty Groups) first."
        )
    return armature


def deforms(armature, obj) -> bool:
    """Whether ``armature`` moves ``obj`` vertex by vertex (a skinned mesh, not a prop or a child)."""
    return any(binding.deforms and binding.armature == armature for binding in armature_bindings(obj))


def bone_parent(obj) -> str | None:
    """Name of the bone carrying ``obj`` (parented to it), or None when it has no bone parent."""
    return next((binding.bone for binding in armature_bindings(obj) if binding.bone is not None), None)


def is_unbound(obj) -> bool:
    """Whether a run may weight ``obj`` when none is named: it follows no
    armature, or its first binding is a bone carrying it (the run leaves
    such a prop rigid and says so)."""
    bindings = armature_bindings(obj)
    return not bindings or bindings[0].bone is not None


def followers(armature) -> list:
    """The objects of the file whose shape or place hangs on ``armature``'s
    bones: those it deforms or carries (:func:`armature_bindings`) and any
    other child of it (an empty on a bone, a curve), in the file's order."""
    return [obj for obj in bpy.data.objects if obj.parent == armature
            or any(binding.armature == armature for binding in armature_bindings(obj))]


def posing_armatures(objects) -> list:
    """The armatures whose pose moves ``objects`` (deforming them or carrying
    them on a bone), each once, in the objects' order; None entries and
    non-meshes are skipped."""
    armatures = [binding.armature for obj in objects if obj is not None and obj.type == "MESH"
                 for binding in armature_bindings(obj) if binding.deforms or binding.bone is not None]
    return list(dict.fromkeys(armatures))


@contextmanager
def pose_position(armatures, position: str = "REST"):
    """Show ``armatures`` in ``position`` ('REST': weights and bind shapes
    belong to it, and some files import posed; or 'POSE') while the block
    runs; each armature's own setting comes back afterwards. The view layer
    is updated on entering and leaving when an armature changed."""
    changed = [armature for armature in dict.fromkeys(armatures) if armature.data.pose_position != position]
    previous = [armature.data.pose_position for armature in changed]
    for armature in changed:
        armature.data.pose_position = position
    try:
        if changed:
            bpy.context.view_layer.update()
        yield
    finally:
        for armature, setting in zip(changed, previous):
            armature.data.pose_position = setting
        if changed:
            bpy.context.view_layer.update()


def objects_at_rest(objects):
    """:func:`pose_position` 'REST' for the armatures posing ``objects``
    (:func:`posing_armatures`): their rest shape and rest place are read inside."""
    return pose_position(posing_armatures(objects))


def clear_parent_keep_world(obj) -> None:
    """Unparent ``obj`` where it stands."""
    world = obj.matrix_world.copy()
    obj.parent = None
    obj.parent_type = "OBJECT"
    obj.parent_bone = ""
    obj.matrix_basis = world


def unbind(obj) -> None:
    """Detach a mesh from every armature it follows: its Armature
    modifiers, its vertex groups named after their bones and an armature
    parent go; its world transform stays."""
    armatures = {binding.armature for binding in armature_bindings(obj)}
    bone_names = {bone.name for armature in armatures for bone in armature.data.bones}
    for modifier in [m for m in obj.modifiers if m.type == "ARMATURE"]:
        obj.modifiers.remove(modifier)
    for group in [g for g in obj.vertex_groups if g.name in bone_names]:
        obj.vertex_groups.remove(group)
    if obj.parent in armatures:
        clear_parent_keep_world(obj)


def remove_armature(armature) -> None:
    """Delete an armature object, and its data when nothing else uses it."""
    data = armature.data
    bpy.data.objects.remove(armature, do_unlink=True)
    if data is not None and data.users == 0:
        bpy.data.armatures.remove(data)
