"""Graph networks in numpy: the foundation every learned part of the add-on
runs on inside Blender, below ``skinning/`` and ``rigging/``.

* :mod:`.spec`: what defines a network once (its :class:`~.spec.NetworkSpec`:
  names, parameter layout, forward, training settings, shipped weights);
* :mod:`.operations`: the table of kernels a forward is written against,
  and :mod:`.numpy_kernels`, the numpy one (the torch one is in the
  training package, ``autorig_addon/training/nn/torch_kernels.py``);
* :mod:`.layers`, :mod:`.aggregation`, :mod:`.convolution`: the layers
  built of those kernels, written once for both (MLP, segment reductions
  by name, EdgeConv, GMEdgeConv, SkinningNet's multi-aggregator convolution);
* :mod:`.graph`: edge indices (mesh one-ring, geodesic balls, vertex to
  nearest bones, bone hierarchy);
* :mod:`.weights_io`: weight files (flat ``state_dict``-named arrays in ``.npz``).

Nothing here imports torch; the training package imports from here, never
the reverse (``tests/test_core_without_blender.py`` checks).
"""
