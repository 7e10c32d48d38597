"""Where the skeleton networks' shipped weights lie."""

from pathlib import Path

#: Folder of the shipped weights, one ``NAME.npz`` per network.
TRAINED_FOLDER = Path(__file__).resolve().parent.parent / "trained"
