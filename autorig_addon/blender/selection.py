"""Which objects a job runs on: names resolved to objects, and what a job
picks when nothing is named.

- **Names**: comma-separated lists (:func:`split_names`), objects by name
  with a message listing what exists (:func:`object_named` in the open
  scene, :func:`find_object` in a loaded file).
- **Default targets**: a transfer started from the panel or a script
  weights the selected meshes other than the source, plus the panel's
  Target (:func:`selected_targets`); one started from the command line
  every mesh of the file not bound to an armature, props on a bone
  included, which the job leaves rigid (:func:`unbound_meshes`). Skin
  weights and Auto-Rig take the selected meshes from the panel, every mesh
  of the file (:func:`file_meshes`) from the command line; the jobs then
  leave out helpers (``object_roles``).
- **Source, armature, character**: the skinned body a transfer copies
  from (:func:`resolve_source`), the armature and meshes to skin
  (:func:`resolve_skin_inputs`, :func:`skin_objects`), the character to rig
  (:func:`selected_meshes`, :func:`character_name`), the bones to transfer
  (:func:`chosen_bone_names`).

Refusals say how to name what is missing, as the job was started.
"""

from __future__ import annotations

from dataclasses import dataclass

import bpy

from ..core.errors import InputError
from ..core.transfer.options import SELECTED_BONES
from . import convert
from .armature_binding import bound_armature, is_unbound

#: Most object names listed in a "no such object" message.
MAX_LISTED_NAMES = 40


# --------------------------------------------------------------------------- names


def split_names(text: str) -> list[str]:
    """Names from a comma-separated string, blanks dropped."""
    return [name.strip() for name in text.split(",") if name.strip()]


def names_in(texts: list[str]) -> list[str]:
    """The names of repeated, comma-separated options (``--target A,B --target C``)."""
    return [name for text in texts for name in split_names(text)]


def object_named(name: str):
    """The object called ``name`` in the open file; a refusal lists its meshes."""
    obj = bpy.data.objects.get(name)
    if obj is None:
        meshes = sorted(o.name for o in bpy.data.objects if o.type == "MESH")
        raise InputError(f"There is no object named '{name}'. Mesh objects here: {', '.join(meshes) or 'none'}.")
    return obj


def find_object(name: str, object_type: str | None = None):
    """The object called ``name`` (optionally of ``object_type``, e.g. 'MESH')
    in a loaded file.

    Raises
    ------
    InputError naming the objects that do exist.
    """
    obj = bpy.data.objects.get(name)
    if obj is not None and (object_type is None or obj.type == object_type):
        return obj
    candidates = sorted(o.name for o in bpy.data.objects if object_type is None or o.type == object_type)
    listed = ", ".join(candidates[:MAX_LISTED_NAMES]) + (" ..." if len(candidates) > MAX_LISTED_NAMES else "")
    kind = f"{object_type.lower()} object" if object_type else "object"
    if obj is not None:
        raise InputError(
            f"'{name}' has type {obj.type.title()}, expected {object_type.title()}. "
            f"Available {kind}s: {listed or 'none'}."
        )
    raise InputError(f"No {kind} named '{name}'. Available: {listed or 'none'}.")


# --------------------------------------------------------------------------- transfer: source and targets


@dataclass(frozen=True)
class HowToPick:
    """How refusals tell the user to name the source and the targets, which
    depends on how the transfer was started.

    Attributes
    ----------
    source : str, completes "make the body the active object or ..."
    targets : str, completes "select the meshes to weight together with the source, or ..."
    """

    source: str
    targets: str


#: From the AutoRig panel's button (the operator's ``invoke``).
PICK_IN_PANEL = HowToPick("pick it as Source in the AutoRig panel", "pick a Target in the AutoRig panel")
#: From a script (``bpy.ops.autorig.transfer_weights(...)`` runs ``execute``
#: alone, so the panel's Source and Target are not read).
PICK_IN_SCRIPT = HowToPick(
    "pass it by name (bpy.ops.autorig.transfer_weights(source='Body', ...))",
    "pass them by name (bpy.ops.autorig.transfer_weights(targets='Shirt,Trousers', ...))",
)


def is_skinned_mesh(obj) -> bool:
    """A mesh with vertex groups bound to an armature (a transfer's source)."""
    return obj.type == "MESH" and len(obj.vertex_groups) > 0 and bound_armature(obj) is not None


def resolve_source(context, name: str, how: HowToPick = PICK_IN_PANEL):
    """The source object: ``name`` if given, else the active skinned mesh,
    else the only skinned mesh among the selected objects; refusals say
    how to name it the way ``how`` describes."""
    names = split_names(name)
    if len(names) > 1:
        raise InputError(
            f"Several sources were given ({', '.join(names)}): transfer from one body at a time, "
            "or join the body meshes into one object first."
        )
    if names:
        source = object_named(names[0])
        convert.require_mesh_object(source, "source")
        return source
    active = context.view_layer.objects.active
    selected = list(context.selected_objects)
    if active is not None and active in selected and is_skinned_mesh(active):
        return active
    candidates = [obj for obj in selected if is_skinned_mesh(obj)]
    if len(candidates) > 1:
        raise InputError(
            f"Several selected meshes are skinned ({', '.join(sorted(o.name for o in candidates))}): "
            f"make the body the active object or {how.source}."
        )
    if not candidates:
        raise InputError(f"No source: make the skinned body the active object or {how.source}.")
    return candidates[0]


def selected_targets(selected_objects, source, extra=None) -> list:
    """The meshes a transfer from the panel or a script weights when none
    is named: the selected meshes other than ``source`` (an object or its
    name), in selection order, then ``extra`` (the panel's Target; may be
    None) unless it is among them or is the source."""
    is_source = (lambda obj: obj.name == source) if isinstance(source, str) else (lambda obj: obj == source)
    targets = [obj for obj in selected_objects if obj.type == "MESH" and not is_source(obj)]
    if extra is not None and extra not in targets and not is_source(extra):
        targets.append(extra)
    return targets


def resolve_targets(context, names: str, source, extra=None, how: HowToPick = PICK_IN_PANEL) -> list:
    """Target objects: the comma-separated ``names``, or when empty
    :func:`selected_targets` (``extra`` may be None); a refusal says how to
    name them the way ``how`` describes."""
    if split_names(names):
        targets = [object_named(name) for name in split_names(names)]
    else:
        targets = selected_targets(context.selected_objects, source, extra)
    unique = list(dict.fromkeys(targets))
    if not unique:
        raise InputError(f"No target: select the meshes to weight together with the source, or {how.targets}.")
    return unique


def file_meshes() -> list:
    """Every mesh object of the loaded file."""
    return [obj for obj in bpy.data.objects if obj.type == "MESH"]


def unbound_meshes(source) -> list:
    """The meshes a transfer from the command line weights when none is
    named: every mesh of the file other than ``source`` that
    :func:`.armature_binding.is_unbound` (props on a bone included: the
    transfer leaves them rigid and says so, and leaves out helper objects)."""
    return [obj for obj in file_meshes() if obj != source and is_unbound(obj)]


def selected_pose_bone_names(armature) -> tuple:
    """Names of the armature's selected pose bones (Blender 4.2 to 5.x)."""
    names = []
    for pose_bone in armature.pose.bones:
        # Blender 5 stores bone selection on the pose bone, 4.x on the bone.
        selected = getattr(pose_bone, "select", None)
        if selected is None:
            selected = pose_bone.bone.select
        if selected:
            names.append(pose_bone.name)
    return tuple(names)


def chosen_bone_names(names: str, subset: str, armature) -> tuple | None:
    """The bones to transfer: the comma-separated ``names`` if any, else the
    selected pose bones of ``armature`` when ``subset`` is
    ``SELECTED_BONES``, else None (every deform bone)."""
    if split_names(names):
        return tuple(split_names(names))
    if subset == SELECTED_BONES:
        return selected_pose_bone_names(armature)
    return None


# --------------------------------------------------------------------------- skin: armature and meshes


def resolve_skin_inputs(context, armature_name: str = "", mesh_names: str = ""):
    """The armature and meshes to skin in the open file: named ones, else the
    selection (the active or only selected armature and the selected meshes)."""
    if armature_name:
        armature = find_object(armature_name, "ARMATURE")
    else:
        armatures = [obj for obj in context.selected_objects if obj.type == "ARMATURE"]
        active = context.active_object
        if active is not None and active.type == "ARMATURE":
            armature = active
        elif len(armatures) == 1:
            armature = armatures[0]
        else:
            raise InputError("Select one armature (and the meshes to skin), or name it.")
    if mesh_names.strip():
        meshes = [find_object(name, "MESH") for name in split_names(mesh_names)]
    else:
        meshes = [obj for obj in context.selected_objects if obj.type == "MESH"]
    return armature, meshes


def file_armature(armature_name: str = ""):
    """The armature of a loaded file a command works on: the named one, else the file's only armature."""
    if armature_name:
        return find_object(armature_name, "ARMATURE")
    armatures = [obj for obj in bpy.data.objects if obj.type == "ARMATURE"]
    if len(armatures) != 1:
        found = ", ".join(obj.name for obj in armatures) or "none"
        raise InputError(f"The file must hold exactly one armature, or name it with --armature (found: {found}).")
    return armatures[0]


def skin_objects(armature_name: str, mesh_names: list[str]):
    """The armature and meshes a skin run binds in a loaded file: the named
    ones (``mesh_names``: repeated or comma-separated names), else the
    file's only armature and every mesh (the job leaves out helpers such as
    bone shapes and leaves props parented to a bone rigid)."""
    armature = file_armature(armature_name)
    names = names_in(mesh_names)
    if names:
        return armature, [find_object(name, "MESH") for name in names]
    meshes = file_meshes()
    if not meshes:
        raise InputError("The file holds no mesh to skin.")
    return armature, meshes


# --------------------------------------------------------------------------- rig: the character


def selected_meshes(context) -> list:
    """The selected mesh objects, by name (one character to rig)."""
    return sorted((obj for obj in context.selected_objects if obj.type == "MESH"), key=lambda obj: obj.name)


def character_name(meshes: list, active=None) -> str:
    """The character's name: the active mesh's if it is one of ``meshes``, else the first's."""
    return (active if active in meshes else meshes[0]).name
