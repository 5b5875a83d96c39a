"""Text from outside (the model file's path, its fit date) made safe for the generated code's
comments.

The provenance comment of every generated file quotes the model file's path and what the model
file says of its fit. A folder named ``x*`` put ``*/`` into the C comment, which closed it and
broke the build; a newline in a folder name began a new line in every ``.m`` file, outside the
``%`` comment, and so executable. Each value is kept on one printable line, and in C the
sequences that end or open a comment or form a trigraph are broken up.
"""

from __future__ import annotations

import re

__all__ = ["c_comment_text", "comment_text"]

# C99 translation phase 1 replaces trigraphs (gcc -std=c99 does) before comments are seen:
# ``??/`` is a backslash. A "?" followed by another "?" gets a backslash after it.
_TRIGRAPH_START = re.compile(r"\?(?=\?)")


def comment_text(text: object) -> str:
    """`text` as one printable line: every character `str.isprintable` refuses (newline,
    carriage return, tab, other control characters, Unicode line and paragraph separators) is
    written as its Python escape (``\\n``, ``\\x1b``, ``\\u2028``)."""
    return "".join(ch if ch.isprintable() else repr(ch)[1:-1] for ch in str(text))


def c_comment_text(text: object) -> str:
    """`comment_text` for a C ``/* ... */`` comment: also ``*/`` (which would end it) as
    ``*\\/``, ``/*`` (a warning with ``-Wall``) as ``/\\*``, and no trigraph (``??/`` is a
    backslash in C99): text that stays inside the comment, on one line, and compiles without
    a warning."""
    line = _TRIGRAPH_START.sub("?\\\\", comment_text(text))
    return line.replace("*/", "*\\/").replace("/*", "/\\*")
