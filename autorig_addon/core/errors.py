"""Exceptions whose message is shown to the artist as it is."""


class InputError(ValueError):
    """The input cannot be processed; the message says why and what to do."""


class Cancelled(RuntimeError):
    """The user cancelled a long operation; nothing was written."""
