"""Numbers of text lines, parsed with numpy, one count per line (the rows of every text reader).

The readers of text formats (OBJ, OFF, ASCII PLY, PCD, CSV / XYZ / PTS)
parse all their numbers at once with numpy and count the numbers of each
line in the same pass (a few vectorised passes over the bytes), so that a
row of the wrong length is found and named by its line number instead of
shifting every value after it into the wrong point or face.
"""

from __future__ import annotations

import warnings

import numpy as np

from ..errors import MeshFileError

__all__ = [
    "numbers",
    "numbers_per_line",
    "numbers_by_line",
    "first_bad_line",
    "line_of",
    "line_of_match",
    "not_a_number",
    "row_error",
    "names_shown",
    "body_rows",
    "fixed_rows",
    "BYTE_ORDER_MARK",
    "without_bom",
]

_NEWLINE = 10
#: The UTF-8 byte-order mark that Excel ("CSV UTF-8"), Notepad and other Windows tools write first
#: in a text file: no part of the first line (kept, it made the first OBJ vertex line unreadable, so
#: that every face pointed one vertex further, and refused every other text format).
BYTE_ORDER_MARK = b"\xef\xbb\xbf"
_CHUNK = 4096  # lines tried at once when looking for the one that is not numbers


def without_bom(data: bytes) -> bytes:
    """``data`` without a leading UTF-8 byte-order mark (:data:`BYTE_ORDER_MARK`); line numbers unchanged."""
    return data[len(BYTE_ORDER_MARK) :] if data.startswith(BYTE_ORDER_MARK) else data


def numbers(text: bytes) -> np.ndarray | None:
    """The whitespace-separated numbers of ``text`` as float64, or None if one is not a number."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            return np.fromstring(text, dtype=np.float64, sep=" ")
    except (ValueError, DeprecationWarning):
        return None


def _words_per_line(text: bytes) -> np.ndarray:
    """How many whitespace-separated words each line of ``text`` (ending with a newline) holds."""
    if not text:
        return np.zeros(0, dtype=np.int64)
    buffer = np.frombuffer(text, dtype=np.uint8)
    # blanks and every control byte (one comparison, faster than a table look-up: benchmarks/docstring_figures.md);
    # a control byte that is not a blank stops numpy's parse, so the caller never uses these counts for such a text
    white = buffer <= 32
    starts = ~white
    starts[1:] &= white[:-1]
    line_starts = np.concatenate([[0], np.flatnonzero(buffer == _NEWLINE)[:-1] + 1])
    return np.add.reduceat(starts, line_starts, dtype=np.int64)


def numbers_by_line(text: bytes) -> tuple[np.ndarray, np.ndarray] | None:
    """``(values, counts)``: every number of ``text`` in order and how many each of its lines holds.

    ``counts`` has one entry per line (``text.count(b"\\n") + 1`` lines when
    ``text`` does not end with a newline; blank lines count 0). None when a
    word is not a number, or reads as more or fewer than one number.
    """
    if not text.endswith(b"\n"):
        text += b"\n"
    values = numbers(text)
    if values is None:
        return None
    counts = _words_per_line(text)
    if counts.sum() != values.size:  # a word numpy reads as two numbers or none ("1-2", "1.5.3")
        return None
    return values, counts


def numbers_per_line(lines: list) -> tuple[np.ndarray, np.ndarray] | None:
    """``(values, counts)`` of a list of lines (each without its newline); see :func:`numbers_by_line`."""
    if not lines:
        return np.zeros(0), np.zeros(0, dtype=np.int64)
    return numbers_by_line(b"\n".join(lines))


def first_bad_line(text: bytes) -> tuple[int, bytes]:
    """``(index, word)``: the first line of ``text`` (0-based) holding a word that is not one number.

    For error messages only (the lines are tried in chunks, then one by one);
    ``(-1, b"")`` when every line reads.
    """
    lines = text.split(b"\n")
    for start in range(0, len(lines), _CHUNK):
        chunk = lines[start : start + _CHUNK]
        if numbers_by_line(b"\n".join(chunk)) is not None:
            continue
        for offset, line in enumerate(chunk):
            for word in line.split():
                if numbers_by_line(word) is None:
                    return start + offset, word
    return -1, b""


def line_of(data: bytes, position: int) -> int:
    """The 1-based number of the line of ``data`` holding byte ``position``."""
    return data.count(b"\n", 0, position) + 1


def line_of_match(data: bytes, pattern, index: int) -> int:
    """The line number of the ``index``-th match of the regular expression ``pattern`` in ``data`` (for messages)."""
    return next(line_of(data, m.start()) for i, m in enumerate(pattern.finditer(data)) if i == index)


def not_a_number(path, text: bytes, first_line, what: str = "") -> MeshFileError:
    """The error for a word of ``text`` that is not a number, naming its line.

    ``first_line`` is the file's line number of the first line of ``text``,
    or a function from a line index of ``text`` (0-based) to the file's line
    number (when ``text`` is lines picked from the file).
    """
    index, word = first_bad_line(text)
    tail = f" ({what})" if what else ""
    if index < 0:
        return MeshFileError(f"{path}: something is not a number{tail}")
    line = first_line(index) if callable(first_line) else first_line + index
    return MeshFileError(f"{path}: line {line}: {word[:30].decode('utf-8', 'replace')!r} is not a number{tail}")


def row_error(path, line: int, found: int, expected, meaning: str = "") -> MeshFileError:
    """``<path>: line <n>: <found> values, expected <expected> (<meaning>)``."""
    noun = "value" if found == 1 else "values"
    tail = f" ({meaning})" if meaning else ""
    return MeshFileError(f"{path}: line {line}: {found} {noun}, expected {expected}{tail}")


def names_shown(names, limit: int = 8) -> str:
    """``x, y, z`` (at most ``limit`` names, then how many more)."""
    names = list(names)
    shown = ", ".join(names[:limit])
    return shown + (f" and {len(names) - limit} more" if len(names) > limit else "")


def body_rows(data: bytes, offset: int, path, n_rows: int | None = None):
    """The rows of numbers of ``data[offset:]`` (an ASCII body after its header), one per non-blank line.

    Returns ``(values, counts, first_value, lines)``: every number in order,
    and for each non-blank line its count of numbers, the index of its first
    number in ``values`` and its 1-based line number in ``data``. With
    ``n_rows``, the body is parsed only up to its ``n_rows``-th non-blank line
    (the elements after those rows are not read). A word that is not a number
    is a :class:`MeshFileError` naming its line.
    """
    body = data[offset:]
    first_line = line_of(data, offset)
    text = body
    if n_rows is not None:
        ends = np.flatnonzero(np.frombuffer(body, dtype=np.uint8) == _NEWLINE)
        cut = n_rows
        while True:  # parse n_rows lines; more if some of them are blank
            text = body[: ends[cut - 1] + 1] if 0 < cut <= ends.size else body if cut > ends.size else b""
            parsed = numbers_by_line(text) if text else (np.zeros(0), np.zeros(0, dtype=np.int64))
            if parsed is None or text is body or np.count_nonzero(parsed[1]) >= n_rows:
                break
            cut += n_rows - int(np.count_nonzero(parsed[1]))
    else:
        parsed = numbers_by_line(body)
    if parsed is None:
        raise not_a_number(path, text, first_line)
    values, counts = parsed
    rows = np.flatnonzero(counts)
    found = counts[rows]
    return values, found, np.cumsum(found) - found, first_line + rows


def fixed_rows(values, counts, first_value, lines, width: int, path, meaning: str) -> np.ndarray:
    """The rows of a table of ``width`` numbers each, as an (n, width) array; a row of another length is named."""
    wrong = counts != width
    if wrong.any():
        i = int(np.argmax(wrong))
        raise row_error(path, int(lines[i]), int(counts[i]), width, meaning)
    if counts.size == 0:
        return np.zeros((0, width))
    start = int(first_value[0])
    return values[start : start + counts.size * width].reshape(counts.size, width)
