"""Options of skeleton prediction: the clustering that turns the joint
votes into a skeleton (:data:`RIG_OPTIONS`, the keywords of
:func:`.predict.skeleton_from_votes`) and what Auto-Rig does with meshes
already bound (:data:`REPLACE_BINDING`). The Rig panel, the Predict
Skeleton and Auto-Rig operators and ``python -m autorig_addon rig`` are
made from them (``core.options``); defaults and bounds are
:mod:`.predict`'s.
"""

from __future__ import annotations

from ..options import FRACTION, Option, option_table
from . import predict

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
)

#: Auto-Rig's choice for meshes already bound to an armature (the panel's and
#: the operator's; the ``rig`` command's ``--replace`` removes the file's
#: armatures instead).
REPLACE_BINDING = Option(
    "replace", bool, False, "Replace Binding",
    "Meshes already bound to an armature lose that binding (its Armature modifier and bone groups) and are bound "
    "to the new skeleton, and the old armature is removed when nothing else follows it; otherwise they are refused",
    flag=None)
