"""Training the graph networks: the torch twins of the numpy kernels.

Every module in this sub-package may import torch, and only these may:
nothing the add-on loads inside Blender imports from here, and the extension zip
leaves this folder out. ``tests/test_core_without_blender.py`` enforces
both. This ``__init__`` itself imports nothing, so listing the package
does not load torch.

Each module mirrors a numpy module of :mod:`autorig_addon.core.nn` with the
same function names and signatures (:mod:`.aggregation`, :mod:`.layers`,
:mod:`.convolution`), and :mod:`.export` turns a trained module into the
weights dict the numpy forward pass reads.
"""
