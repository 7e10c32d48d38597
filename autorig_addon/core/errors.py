"""What each exception means, written once for the core, the operators and
the command line.

:class:`InputError`
    The input cannot be processed and the user can fix it: a wrong object,
    missing weights, objects far apart, a file that does not exist. The
    message is shown to the artist as it is, so it says what is wrong and
    how to fix it. An operator reports it as an error, returns
    ``{'CANCELLED'}`` and leaves the scene unchanged (nothing is written
    before everything is computed). On the command line an input that fails
    with it is recorded in the JSON summary's ``failed`` list and the batch
    goes on; the run then exits 1. One that stops a whole subcommand (e.g.
    ``package`` cannot download a wheel) prints ``error: MESSAGE`` and exits 1.
:class:`Cancelled`
    The user stopped a long operation (Esc); nothing was written. An
    operator reports it as a warning and returns ``{'CANCELLED'}``.
Usage errors
    The command line itself is wrong: an unknown option, a value out of
    bounds, no input file found, an unknown method. ``argparse`` or
    ``autorig_addon.cli.exit_codes.UsageError`` reports it and the command
    exits 2 without running anything.
Anything else
    A bug or an environment failure (out of memory, a full disk, a broken
    installation). It is not caught: it propagates with its traceback
    (the command line still records it per input in a batch, so one bad
    file does not stop the others).
"""


class InputError(ValueError):
    """The input cannot be processed; the message says why and what to do."""


class Cancelled(RuntimeError):
    """The user cancelled a long operation; nothing was written."""
