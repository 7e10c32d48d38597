"""``python -m autorig_addon rig``: predict a skeleton for the meshes of a
file and (unless ``--skin none``) bind them to it with skin weights.

Each input holds one character: the meshes named with ``--mesh``, else
every mesh of the file except helpers (bone shapes, objects hidden from
render). A file holding several characters apart is refused, naming them:
rig each with ``--mesh``. Rigid props of their own (a sword, a shield) get
no bones: they are bound wholly to the bone holding them
(``core.rigging.props``). A file that already holds an
armature is refused unless ``--replace``, which removes the armatures, the
meshes' Armature modifiers and the vertex groups named after their bones
first, and takes what the bones carried (KayKit's swords) off them where it
is at rest; what a bone carried that sticks out of the skinned meshes is a
held prop by the artist's own rig, twin or not (a sword in each hand), bound
wholly to the new bone nearest the old one. The options are made from the rig option table
(``core.rigging.options.RIG_OPTIONS``), the one the Blender panel is made
from; ``--skin`` takes the skinning methods of ``core.skinning.methods``.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from ..core.errors import InputError
from ..core.messages import listed_names
from ..core.rigging.options import RIG_OPTIONS
from ..core.skinning.methods import DEFAULT_SKIN_METHOD, SKIN_METHODS
from ..core.skinning.options import SKINNING_OPTIONS
from .arguments import add_option, add_options
from .batch import add_batch_arguments, run_batch

NAME = "rig"
HELP = "Predict a skeleton for a character's meshes and bind them to it (auto-rig)"
#: The ``--skin`` choice that leaves the meshes unbound.
NO_SKIN = "none"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_batch_arguments(parser)
    parser.add_argument("--mesh", action="append", default=[], metavar="OBJ",
                        help="Mesh of the character to rig (repeat, or comma-separate; default: every mesh except bone "
                             "shapes): one character of a file holding several")
    add_options(parser, RIG_OPTIONS)
    parser.add_argument(
        "--skin", choices=SKIN_METHODS + (NO_SKIN,), default=DEFAULT_SKIN_METHOD,
        help=f"How the meshes are weighted to the new skeleton ({NO_SKIN}: the armature alone, meshes unbound; "
             f"default {DEFAULT_SKIN_METHOD}; see the skin subcommand)",
    )
    add_option(parser, SKINNING_OPTIONS["rigid_parts"])
    parser.add_argument("--rigify", action="store_true",
                        help="Build Rigify's control rig (IK/FK limbs, torso and head controls) from the standard "
                             "skeleton and bind the meshes to its DEF- bones (needs a biped or quadruped: the "
                             "template auto recognising one, or --template biped/quadruped); the metarig stays in "
                             "the file, hidden")
    parser.add_argument("--keep-poor", action="store_true",
                        help="Keep a skeleton the checks find poor (a bone outside the body, legs not hanging from the "
                             "hips, ...) and list what they found in the summary (default: the file fails with the "
                             "reason and nothing is written)")
    parser.add_argument("--replace", action="store_true",
                        help="Rig a file that already holds an armature: remove it, the meshes' Armature modifiers "
                             "and their groups named after its bones first (default: such a file is refused)")


def clear_armatures(replace: bool) -> tuple[list[str], dict]:
    """Remove every armature of the loaded file and unbind the meshes from
    them when ``replace``; otherwise refuse a file that holds one.

    Returns
    -------
    names : the names of the removed armatures
    carried : dict mapping each mesh an armature that deformed other meshes
        carried on one bone (KayKit's weapons, shields, helmet, cape) to that
        bone's middle at rest, world space (``blender.object_roles.carried_on_bones``):
        ``plan_rig``'s ``carried``
    """
    import bpy

    from ..blender.armature_binding import clear_parent_keep_world, pose_position, remove_armature, unbind
    from ..blender.object_roles import carried_on_bones
    from ..blender.selection import file_meshes

    armatures = [obj for obj in bpy.data.objects if obj.type == "ARMATURE"]
    if not armatures:
        return [], {}
    names = [obj.name for obj in armatures]
    if not replace:
        raise InputError(f"The file already holds an armature ({listed_names(names, quoted=True)}): pass --replace "
                         "to remove it and rig the meshes anew.")
    # At rest: the unbound meshes take their rest shape, so what the bones carried (a sword on the hand's bone)
    # must stay where it is at rest too, not where the file's pose held it.
    carried = carried_on_bones(file_meshes())
    with pose_position(armatures):
        for obj in file_meshes():
            unbind(obj)
        for obj in bpy.data.objects:
            if obj.parent in armatures:
                clear_parent_keep_world(obj)
    for armature in armatures:
        remove_armature(armature)
    return names, carried


def run(args: argparse.Namespace) -> int:
    from ..blender.jobs.rig import RigSettings, plan_rig_steps, planned_rig_steps, run_steps
    from ..blender.jobs.skin import SkinSettings
    from ..core.skinning.options import SkinningOptions

    settings = RigSettings(args.bandwidth, args.density_threshold, args.symmetry, args.template, args.names,
                           args.fingers)
    skin = None if args.skin == NO_SKIN else SkinSettings(SkinningOptions(method=args.skin,
                                                                          rigid_parts=args.rigid_parts))

    def process(input_path, output_path, progress):
        import bpy

        from ..blender import scene_io
        from ..blender.object_roles import without_helpers
        from ..blender.selection import file_meshes, find_object, names_in

        scene_io.load_scene(input_path)
        named = names_in(args.mesh)
        # Helpers (bone shapes) are told apart while their armature is still there.
        meshes = [find_object(name, "MESH") for name in named] if named else without_helpers(file_meshes())
        removed, carried = clear_armatures(args.replace)
        if not meshes:
            raise InputError("The file holds no mesh to rig.")
        # Named meshes are one character of the file: the armature takes the first one's name.
        character = meshes[0].name if named else Path(input_path).stem
        plan_steps = plan_rig_steps(meshes, bpy.context.evaluated_depsgraph_get(), character, settings,
                                    skin=skin, named=bool(named), rigify=args.rigify, keep_poor=args.keep_poor,
                                    carried=carried)
        result = run_steps(planned_rig_steps(bpy.context, plan_steps, remember=False), progress)
        progress(1.0, "Saving")
        scene_io.save_scene(output_path)
        details = {"armature": result.armature.name, "bones": result.skeleton.bone_count,
                   "meshes": [obj.name for obj in result.meshes], "skin": args.skin, "template": result.template,
                   "body": result.body, "confidence": round(result.confidence, 3),
                   "key_joints_from": result.key_joints_from or None, "kind_from": result.kind_from or None,
                   "rig_from": result.rig_from or None,
                   "rigify": result.rigify,
                   "problems": list(result.problems)}
        if removed:
            details["replaced"] = removed
        notes = list(result.notes) + (result.skin_plan.notes if result.skin_plan is not None else [])
        if notes:
            details["notes"] = notes
        return details

    return run_batch(args.inputs, args.out, args.format, process, args.summary, args.quiet)
