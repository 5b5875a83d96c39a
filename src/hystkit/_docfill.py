"""Docstring entries written once (MNE-Python's ``docdict`` / ``fill_doc``, scipy's
``doccer``): a line of a docstring that holds only ``%(name)s`` is replaced by the entry
``name``, indented as that line. The models keep their entries in ``models._docs``; the
entries of the functions that write a file (``io``, ``compensation``) are :data:`OUTPUT_ENTRIES`
here, filled by :func:`fill_output_doc`.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from typing import TypeVar

__all__ = ["OUTPUT_ENTRIES", "docfiller", "fill", "fill_output_doc"]

F = TypeVar("F", bound=Callable)

_LINE = re.compile(r"^( *)%\((\w+)\)s$", re.MULTILINE)


def fill(doc: str, entry: Callable[[str], str]) -> str:
    """`doc` with each line ``%(name)s`` replaced by ``entry(name)``, indented as that line.

    Parameters
    ----------
    doc : str
        A docstring.
    entry : callable
        ``entry(name) -> text`` of the entry (its lines unindented).

    Returns
    -------
    str
        The docstring filled in.
    """
    def replace(match: re.Match) -> str:
        indent, key = match.groups()
        return "\n".join(indent + line if line else line for line in entry(key).split("\n"))

    return _LINE.sub(replace, doc)


def docfiller(entry: Callable[[str], str]) -> Callable[[F], F]:
    """A decorator that fills a function's docstring in place (:func:`fill`).

    Parameters
    ----------
    entry : callable
        ``entry(name) -> text``, as for :func:`fill`.

    Returns
    -------
    callable
        ``fill_doc(function) -> function``.
    """
    def fill_doc(function: F) -> F:
        function.__doc__ = fill(function.__doc__, entry)
        return function

    return fill_doc


# What every writer of one file `path` with a `force` switch says about it.
OUTPUT_ENTRIES = {
    "force": """force : bool, default False
    Replace an existing file.""",
    # the Returns section and the first entry of the Raises section
    "written_path": """Returns
-------
pathlib.Path
    `path`.

Raises
------
OutputExistsError
    `path` exists and `force` is False.""",
}

fill_output_doc = docfiller(OUTPUT_ENTRIES.__getitem__)
