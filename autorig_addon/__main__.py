"""``python -m autorig_addon``: the command line (see :mod:`autorig_addon.cli`)."""

import sys

from .cli.main import main

sys.exit(main())
