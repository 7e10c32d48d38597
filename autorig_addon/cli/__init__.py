"""Command line: ``python -m autorig_addon SUBCOMMAND ...``.

Works with ``bpy`` installed as a module and inside Blender::

    blender --background --python-expr "import sys; sys.path.insert(0, 'REPO'); \\
        from autorig_addon.cli import main; sys.exit(main(['transfer', ...]))"

One module per concept, dependencies pointing one way (``cli`` imports
``blender`` and ``core``, never the reverse; Blender loads only when a
subcommand runs):

- :mod:`.main`: the parser, the subcommand registry and :func:`main`,
- :mod:`.exit_codes`: exit codes and :class:`~.exit_codes.UsageError`,
- :mod:`.batch`: many inputs, a progress bar on stderr, a JSON summary on stdout,
- :mod:`.arguments`: bounded numbers for argparse and options shared by subcommands,
- :mod:`.transfer`, :mod:`.skin`, :mod:`.evaluate`, :mod:`.package`: one subcommand each,
- :mod:`.evaluation_methods`: the methods ``eval`` scores, registered per task.
"""

from .main import main

__all__ = ["main"]
