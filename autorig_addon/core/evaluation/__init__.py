"""Scoring predicted rigs, skin weights and weight transfers against references.

* :mod:`.skin_metrics`: L1, influence precision/recall and deformation error
  of skin weights (:func:`~.skin_metrics.evaluate_skin`, what ``eval skin``
  prints), and the metrics of a transfer.
* :mod:`.skeleton_metrics`: Chamfer distances of skeletons and
  :func:`~.skeleton_metrics.evaluate_rig`, all skeleton metrics (what
  ``eval rig`` prints).
* :mod:`.joint_matching`: one-to-one matching of joints and the joint IoU,
  precision and recall it gives.
* :mod:`.tree_edit_distance`: edit distance between joint hierarchies,
  independent of child order.
* :mod:`.deformation`: distance between a mesh posed with two weight sets.
* :mod:`.stretch`: edge stretch of a posed mesh.
* :mod:`.deform_weights`: weights as one column per deform bone.
* :mod:`.self_transfer`: the skin-tight target of a self-transfer check.
* :mod:`.report`: summary statistics and markdown tables of a report.
"""
