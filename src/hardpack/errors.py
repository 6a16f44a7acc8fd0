"""Exceptions raised by hardpack.

Every refusal of bad input raises :class:`InvalidInputError` with a message that says what is
wrong, where, and how to fix it.
"""

import numpy as np


class InvalidInputError(ValueError):
    """Input that hardpack refuses: wrong shape, non-finite values, overlaps, unknown keys, ..."""


class StoreError(InvalidInputError):
    """A file that cannot be read as a hardpack dataset (the message names the file)."""


def check_seed(seed) -> None:
    """Refuse a random seed that is not a non-negative integer (bools are refused too).

    Parameters
    ----------
    seed : int
        The seed of a ``numpy.random.default_rng``: a Python or NumPy integer >= 0.

    Raises
    ------
    InvalidInputError
        If ``seed`` is not a non-negative integer.
    """
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise InvalidInputError(f"seed must be a non-negative integer, got {seed!r}")
