"""Options of skeleton prediction: the clustering that turns the joint
votes into a skeleton (:data:`RIG_OPTIONS`, the keywords of
:func:`.predict.skeleton_from_votes`) and what Auto-Rig does with meshes
already bound (:data:`REPLACE_BINDING`), whether it builds Rigify's
control rig (:data:`RIGIFY`) and whether it keeps a poor skeleton
(:data:`KEEP_POOR`). The Rig panel, the Predict
Skeleton and Auto-Rig operators and ``python -m autorig_addon rig`` are
made from them (``core.options``); defaults and bounds are
:mod:`.predict`'s.
"""

from __future__ import annotations

from ..options import FRACTION, Choice, Option, option_table
from ..skeleton import name_presets
from . import predict, standard_skeleton

#: The clustering options, in the panel's order; the panel re-clusters the
#: predicted armature live when one changes.
RIG_OPTIONS = option_table(
    Option("bandwidth", float, predict.DEFAULT_BANDWIDTH, "Bandwidth",
           "Level of detail: reach of the clustering of the joint votes, as a share of the character's largest "
           "side; smaller gives more joints",
           low=predict.MIN_BANDWIDTH, high=predict.MAX_BANDWIDTH, precision=3, step=0.1),
    Option("density_threshold", float, predict.DEFAULT_DENSITY_THRESHOLD, "Density Threshold",
           "Joints whose vote mass is below this share of the strongest are dropped; higher keeps only "
           "well-supported joints",
           low=predict.MIN_DENSITY_THRESHOLD, high=predict.MAX_DENSITY_THRESHOLD, unit=FRACTION, precision=3, step=0.1),
    Option("symmetry", bool, predict.DEFAULT_SYMMETRY, "Symmetry",
           "When the character is left-right symmetric, mirror the joint votes and pair the joints, so the "
           "skeleton is symmetric with .L/.R names"),
    Option("template", str, predict.DEFAULT_TEMPLATE, "Template",
           "Which skeleton to build: a standard biped or quadruped (Rigify's metarig layout and names), the "
           "free-form skeleton of the joint votes, or whichever the shape looks like (a known character's rig when "
           "its body is nearly this one)",
           choices=(
               Choice(standard_skeleton.AUTO, "Auto", "The rig of a known character whose body is nearly this "
                      "one, fitted to it; else a standard biped or quadruped skeleton when the shape clearly is one; "
                      "else the free-form skeleton"),
               Choice(standard_skeleton.BIPED, "Biped", "A standard humanoid skeleton (Rigify's human metarig)"),
               Choice(standard_skeleton.QUADRUPED, "Quadruped",
                      "A standard four-legged skeleton (Rigify's quadruped metarig)"),
               Choice(standard_skeleton.FREE_FORM, "Free-Form",
                      "The skeleton of the joint votes, any shape; the bandwidth sets its detail"))),
    Option("fingers", bool, predict.DEFAULT_FINGERS, "Fingers",
           "Give a standard biped three bones per finger when both hands have separable fingers (a mitten or a "
           "fist gets none, and the report says so); off, each hand is one bone"),
    Option("names", str, name_presets.DEFAULT_PRESET, "Bone Names",
           "How the bones of a standard biped are named: Blender's Rigify, or a game engine's or mocap library's "
           "humanoid names (other skeletons keep Rigify's names)",
           choices=tuple(Choice(preset, name_presets.PRESET_TITLES[preset], label) for preset, label in
                         name_presets.PRESET_LABELS.items())),
)

#: Auto-Rig's choice for meshes already bound to an armature (the panel's and
#: the operator's; the ``rig`` command's ``--replace`` removes the file's
#: armatures instead).
REPLACE_BINDING = Option(
    "replace", bool, False, "Replace Binding",
    "Meshes already bound to an armature lose that binding (its Armature modifier and bone groups) and are bound "
    "to the new skeleton, and the old armature is removed when nothing else follows it; otherwise they are refused",
    flag=None)

#: Auto-Rig's Rigify choice (the panel's and the operator's; the ``rig``
#: command's ``--rigify``).
RIGIFY = Option(
    "rigify", bool, False, "Rigify Control Rig",
    "Build Rigify's control rig (IK/FK limbs, torso and head controls) from the standard skeleton and bind the "
    "meshes to its DEF- bones; needs the Biped or Quadruped template (or Auto recognising one)",
    flag=None)

#: Whether a skeleton the checks find poor (``core.rigging.quality``) is kept
#: (with the problems in the report) instead of refused (the panel's and the
#: operators'; the ``rig`` command's ``--keep-poor``).
KEEP_POOR = Option(
    "keep_poor", bool, False, "Keep Poor Result",
    "Build the skeleton even when the checks find it poor (a bone outside the body, legs not hanging from the hips, "
    "...); the report lists what they found. Otherwise nothing is built and the report says why",
    flag=None)
