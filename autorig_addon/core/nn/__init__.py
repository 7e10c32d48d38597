"""Graph networks: the kernels, layers and weight files the learned
skinning networks share.

Two twins of every kernel exist:

* the numpy modules here (:mod:`.graph`, :mod:`.aggregation`,
  :mod:`.layers`, :mod:`.weights_io`) run the networks inside Blender, where
  torch is absent;
* the torch modules under :mod:`.training` train them, with the same
  function names and signatures, so a forward pass reads the same in both.

The rule that keeps torch out of Blender: **only modules inside the
``training`` sub-package may import torch, and nothing outside it imports
from it**. ``tests/test_core_without_blender.py`` imports every other module
in a fresh interpreter and scans their source, and fails when torch or the
training package is reached; the extension zip leaves the training package
out (``autorig_addon/packaging.py``).

A network's weights are one flat ``{name: array}`` dict whose names are the
torch ``state_dict`` keys (``"conv1.mlp.linears.0.weight"``), so the numpy
forward pass reads the same names the torch module wrote.
"""

#: The sub-package holding every torch-importing module (dotted name
#: relative to ``autorig_addon``); the import guard tests and the extension
#: packaging both recognise torch-only code by it.
TRAINING_PACKAGE = "core.nn.training"
