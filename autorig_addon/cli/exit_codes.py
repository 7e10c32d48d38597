"""Exit codes of the command line and the exception that means "usage error".

Which exception maps to which code is written once, in
:mod:`autorig_addon.core.errors`; this module only names the numbers.
"""

#: Every input succeeded.
EXIT_OK = 0
#: Some input failed (bad file, :class:`~autorig_addon.core.errors.InputError`),
#: or the work itself failed (e.g. ``package`` could not download a wheel).
EXIT_FAILED = 1
#: The command line is wrong: unknown option, bad value, no input found
#: (argparse uses 2 as well).
EXIT_USAGE = 2


class UsageError(Exception):
    """The command line itself is wrong (exit code :data:`EXIT_USAGE`)."""
