"""Hide torch, as if it were not installed: the first pass of scripts/test.sh.

With this folder on ``PYTHONPATH``, Python runs this file at start-up (the
``site`` module imports the first ``sitecustomize`` on ``sys.path``), in the
test process and in every subprocess that inherits the environment. It
replaces the path-based finder in ``sys.meta_path`` by one that finds none of
the packages of the torch wheel, and hides the torch distribution, so that,
exactly as where torch is missing:

* ``import torch`` (and ``torch.*``) raises ``ModuleNotFoundError: No module
  named 'torch'``;
* ``importlib.util.find_spec("torch")`` returns None;
* ``importlib.metadata.version("torch")`` raises ``PackageNotFoundError``.

Everything else is found as before. Only code that walks ``sys.path`` itself
(``importlib.machinery.PathFinder`` called directly, ``pkgutil``) still sees
torch's files. A ``sitecustomize`` that this file shadows is run after it.
"""

import importlib.machinery
import importlib.util
import os
import sys

#: Top-level packages of the torch wheel.
HIDDEN_PACKAGES = frozenset({"torch", "functorch", "torchgen"})
#: Its distribution name (``importlib.metadata``).
HIDDEN_DISTRIBUTIONS = frozenset({"torch"})


def _hidden_distribution(name) -> bool:
    return name is not None and name.lower().replace("-", "_").replace(".", "_") in HIDDEN_DISTRIBUTIONS


class PathFinderWithoutTorch:
    """``importlib.machinery.PathFinder``, finding neither torch's packages
    nor its distribution."""

    @staticmethod
    def find_spec(name, path=None, target=None):
        if name.partition(".")[0] in HIDDEN_PACKAGES:
            return None
        return importlib.machinery.PathFinder.find_spec(name, path, target)

    @staticmethod
    def find_distributions(context=None):
        import importlib.metadata

        if context is None:
            context = importlib.metadata.DistributionFinder.Context()
        if _hidden_distribution(context.name):
            return iter(())
        found = importlib.machinery.PathFinder.find_distributions(context)
        return (d for d in found if context.name is not None or not _hidden_distribution(d.metadata["Name"]))

    @staticmethod
    def invalidate_caches():
        importlib.machinery.PathFinder.invalidate_caches()


def hide_torch() -> None:
    """Put :class:`PathFinderWithoutTorch` where ``PathFinder`` was."""
    for index, finder in enumerate(sys.meta_path):
        if finder is importlib.machinery.PathFinder:
            sys.meta_path[index] = PathFinderWithoutTorch
            return
    raise RuntimeError("sys.meta_path has no PathFinder; cannot hide torch")


def _run_shadowed_sitecustomize() -> None:
    here = os.path.dirname(os.path.abspath(__file__))
    folders = [entry for entry in sys.path if os.path.abspath(entry or os.curdir) != here]
    spec = importlib.machinery.PathFinder.find_spec("sitecustomize", folders)
    if spec is not None and spec.loader is not None:
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)


hide_torch()
_run_shadowed_sitecustomize()
