"""Exceptions raised by hardpack.

Every refusal of bad input raises :class:`InvalidInputError` with a message that says what is
wrong, where, and how to fix it.
"""


class InvalidInputError(ValueError):
    """Input that hardpack refuses: wrong shape, non-finite values, overlaps, unknown keys, ..."""


class StoreError(InvalidInputError):
    """A file that cannot be read as a hardpack dataset (the message names the file)."""
