"""Training the networks (torch): everything that is not needed to run them.

Its paths mirror ``core/``: ``nn/`` holds the torch kernels, the module a
network's spec becomes, the optimiser, the augmentation and the one
training loop (:func:`.nn.fit.fit`); ``skinning/learned/`` and ``rigging/``
build each task's training examples and train its networks; ``command`` is
the ``train`` subcommand. The add-on never imports this package (a test
checks), and the extension zip leaves it out. Importing this ``__init__``
loads nothing, so listing the package does not load torch; the
``training_set`` modules need numpy alone.
"""
