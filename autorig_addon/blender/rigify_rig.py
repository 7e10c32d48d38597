"""A Rigify control rig from a standard skeleton: Rigify's own basic
metarig with its bones moved onto the skeleton (:mod:`..core.rigging.metarig`),
then Rigify's generation.

Rigify ships with Blender as a core add-on; it is enabled here when it is
not (and the report says so). The metarig keeps Rigify's rig types,
connections and options; each moved bone keeps the roll that points its Z
axis where the template's pointed, so the limbs bend the way Rigify expects.
The generated rig's ``DEF-`` bones are the deforming ones. The metarig stays
in the file, hidden, so the artist can adjust it and generate again.

A biped with fingers gets the palm and finger bones of Rigify's full Human
metarig added to the basic one (:func:`..core.rigging.metarig.finger_bones`),
with their rig types, parameters and bone collections (``Fingers``,
``Fingers (Detail)``) as the Human metarig sets them.
"""

from __future__ import annotations

from dataclasses import replace

import addon_utils
import bpy
from mathutils import Vector

from ..core.errors import InputError
from ..core.rigging.metarig import (
    FINGER_COLLECTION,
    FINGER_DETAIL_COLLECTION,
    FINGER_PARAMETERS,
    FINGER_RIG,
    METARIGS,
    PALM_ROTATION_MODE,
    finger_bones,
    metarig_placement,
)
from . import convert
from .armature_binding import remove_armature

#: The add-on module Blender ships Rigify as.
RIGIFY_MODULE = "rigify"
#: Suffix of the metarig kept beside the generated rig.
METARIG_SUFFIX = "_metarig"
#: Connected bones whose head lies this close to their parent's tail (scene
#: units) stay connected after the move.
CONNECT_TOLERANCE = 1e-6


def ensure_rigify() -> str:
    """Enable Rigify if it is not; returns a note when it was enabled ("" otherwise).

    Raises
    ------
    InputError when this Blender has no Rigify.
    """
    loaded_default, loaded_now = addon_utils.check(RIGIFY_MODULE)
    if loaded_now and hasattr(bpy.ops.pose, "rigify_generate"):
        return ""
    try:
        module = addon_utils.enable(RIGIFY_MODULE, default_set=True)
    except Exception as error:  # an add-on's own import error
        raise InputError(f"Rigify could not be enabled ({error}); the plain skeleton is kept.") from error
    if module is None or not hasattr(bpy.ops.pose, "rigify_generate"):
        raise InputError("Rigify is not available in this Blender (Preferences > Add-ons > Rigify); the plain "
                         "skeleton is kept.")
    return "Rigify was enabled to generate the control rig"


def _add_metarig(kind: str, context):
    operator = getattr(bpy.ops.object, f"armature_{METARIGS[kind]}_metarig_add")
    before = set(bpy.data.objects)
    operator()
    added = [obj for obj in bpy.data.objects if obj not in before and obj.type == "ARMATURE"]
    if len(added) != 1:
        raise InputError("Rigify's metarig could not be added.")
    return added[0]


def _place_bones(metarig, placement: dict, removed: tuple, context, added: tuple = ()) -> None:
    """Move the metarig's bones (Edit Mode) to ``placement`` (armature
    space) and add the ``added`` bones (:class:`..core.rigging.metarig.MetarigBone`,
    their ends in armature space)."""
    context.view_layer.objects.active = metarig
    bpy.ops.object.mode_set(mode="EDIT")
    try:
        bones = metarig.data.edit_bones
        for name in removed:
            if name in bones:
                bones.remove(bones[name])
        connected = {bone.name for bone in bones if bone.use_connect}
        for bone in bones:
            bone.use_connect = False
        for name, (head, tail) in placement.items():
            if name not in bones:
                continue
            bone = bones[name]
            up = bone.z_axis.copy()
            bone.head, bone.tail = tuple(head), tuple(tail)
            bone.align_roll(up)
        for name in connected:
            bone = bones.get(name)
            if bone is not None and bone.parent is not None and \
                    (bone.head - bone.parent.tail).length <= CONNECT_TOLERANCE:
                bone.use_connect = True
        for spec in added:
            bone = bones.new(spec.name)
            bone.head, bone.tail = tuple(spec.head), tuple(spec.tail)
            bone.parent = bones[spec.parent]
            bone.use_connect = spec.connected and (bone.head - bone.parent.tail).length <= CONNECT_TOLERANCE
            axis, sign = spec.up
            hand = bones["hand" + spec.name[-2:]]
            bone.align_roll((hand.x_axis if axis == "x" else hand.z_axis) * sign)
    finally:
        bpy.ops.object.mode_set(mode="OBJECT")


def _finger_collections(armature_data) -> tuple:
    """Rigify's finger bone collections (:data:`FINGER_COLLECTION`, the
    detail one), added as the Human metarig has them: their own rows of
    Rigify's layers panel after the torso's, the rows below moved down."""
    collections = armature_data.collections
    torso_rows = [coll.rigify_ui_row for coll in armature_data.collections_all
                  if coll.name.startswith("Torso") and hasattr(coll, "rigify_ui_row")]
    row = (max(torso_rows) if torso_rows else 0) + 2
    for coll in armature_data.collections_all:
        if hasattr(coll, "rigify_ui_row") and coll.rigify_ui_row >= row:
            coll.rigify_ui_row += 3
    made = []
    for name, offset, title, color in ((FINGER_COLLECTION, 0, "", 6), (FINGER_DETAIL_COLLECTION, 1, "(Detail)", 5)):
        coll = collections.get(name) or collections.new(name)
        if hasattr(coll, "rigify_ui_row"):
            coll.rigify_ui_row = row + offset
            coll.rigify_ui_title = title
            if color <= len(getattr(armature_data, "rigify_colors", ())):
                coll.rigify_color_set_id = color
        made.append(coll)
    return tuple(made)


def _set_finger_rigs(metarig, added: tuple) -> None:
    """Rig types, parameters and collections of the ``added`` palm and finger bones (Object Mode)."""
    if not added:
        return
    controls, detail = _finger_collections(metarig.data)
    for spec in added:
        pose_bone = metarig.pose.bones[spec.name]
        controls.assign(pose_bone.bone)
        pose_bone.rigify_type = spec.rig_type
        if spec.name.startswith("palm."):
            pose_bone.rotation_mode = PALM_ROTATION_MODE
        if spec.rig_type == FINGER_RIG:
            parameters = pose_bone.rigify_parameters
            for key, value in FINGER_PARAMETERS:
                if hasattr(parameters, key):
                    setattr(parameters, key, value)
            refs = getattr(parameters, "tweak_coll_refs", None)
            if refs is not None:
                refs.add().set_collection(detail)


def generate_rigify_rig(armature, name: str, context=None) -> tuple:
    """Rigify's control rig for the standard skeleton of ``armature``.

    Returns
    -------
    (rig, metarig, notes): the generated armature object (named ``name``),
    the hidden metarig and notes for the report. ``armature`` is left as it
    is; on failure nothing new stays in the file.

    Raises
    ------
    InputError when the skeleton is not a standard biped or quadruped, or
    Rigify is missing or fails.
    """
    context = context or bpy.context
    skeleton = convert.read_skeleton(armature)
    kind, placement, removed = metarig_placement(skeleton)
    added = finger_bones(skeleton)
    notes = [note for note in (ensure_rigify(),) if note]
    previous_active = context.view_layer.objects.active
    metarig = _add_metarig(kind, context)
    rig = None
    try:
        metarig.matrix_world = armature.matrix_world.copy()
        inverse = armature.matrix_world.inverted()
        local = {bone: (inverse @ Vector(head.tolist()), inverse @ Vector(tail.tolist()))
                 for bone, (head, tail) in placement.items()}
        added = tuple(replace(spec, head=inverse @ Vector(spec.head.tolist()),
                              tail=inverse @ Vector(spec.tail.tolist())) for spec in added)
        _place_bones(metarig, local, removed, context, added)
        _set_finger_rigs(metarig, added)
        metarig.name = metarig.data.name = name + METARIG_SUFFIX
        for obj in context.view_layer.objects:
            obj.select_set(False)
        metarig.select_set(True)
        context.view_layer.objects.active = metarig
        before = set(bpy.data.objects)
        try:
            bpy.ops.pose.rigify_generate()
        except RuntimeError as error:
            raise InputError(f"Rigify could not generate the control rig: {error}".strip()) from error
        rig = metarig.data.rigify_target_rig or next(
            (obj for obj in bpy.data.objects if obj not in before and obj.type == "ARMATURE"), None)
        if rig is None:
            raise InputError("Rigify generated no rig.")
        rig.name = name
        rig.data.name = name
        metarig.hide_set(True)
        notes.append(f"Rigify {kind} control rig generated ({sum(bone.use_deform for bone in rig.data.bones)} "
                     f"DEF- bones deform); its metarig '{metarig.name}' stays hidden, to adjust and generate again")
    except BaseException:
        if rig is not None:
            remove_armature(rig)
        remove_armature(metarig)
        raise
    finally:
        if previous_active is not None and previous_active.name in bpy.data.objects:
            context.view_layer.objects.active = previous_active
    return rig, metarig, notes
