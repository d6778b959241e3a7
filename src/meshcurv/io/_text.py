"""Numbers of text lines, parsed with numpy, one count per line (OBJ and OFF records)."""

from __future__ import annotations

import warnings

import numpy as np

__all__ = ["numbers", "numbers_per_line"]

_WHITE = np.zeros(256, dtype=bool)
_WHITE[[9, 10, 11, 12, 13, 32]] = True


def numbers(text: bytes) -> np.ndarray | None:
    """The whitespace-separated numbers of ``text`` as float64, or None if one is not a number."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            return np.fromstring(text, dtype=np.float64, sep=" ")
    except (ValueError, DeprecationWarning):
        return None


def numbers_per_line(lines: list) -> tuple[np.ndarray, np.ndarray] | None:
    """``(values, counts)``: every number of ``lines`` in order and how many each line holds.

    Returns None when a word is not a number. The counts let a caller take
    the first three numbers of each line (``v x y z w``, ``v x y z r g b``)
    without shifting the next lines when one holds more or fewer.
    """
    if not lines:
        return np.zeros(0), np.zeros(0, dtype=np.int64)
    joined = b" \n".join(lines) + b" \n"
    values = numbers(joined)
    if values is None:
        return None
    text = np.frombuffer(joined, dtype=np.uint8)
    white = _WHITE[text]
    starts = ~white
    starts[1:] &= white[:-1]
    line_starts = np.concatenate([[0], np.flatnonzero(text == 10)[:-1] + 1])
    counts = np.add.reduceat(starts, line_starts, dtype=np.int64)
    if counts.sum() != values.size:  # a word numpy reads as two numbers or none
        return None
    return values, counts
