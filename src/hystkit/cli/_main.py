"""``hystkit`` command line: each subcommand parses, calls the library, writes, returns a code.

Subcommands live in ``cmd_*.py`` modules beside this one, each with a ``register(sub)``
function; they are found here so that adding a capability does not edit a shared file.
"""

from __future__ import annotations

import importlib
import os
import pkgutil
import sys
from collections.abc import Sequence

from .. import __version__
from ..errors import HystkitError
from ._common import Parser

__all__ = ["main"]


def _parser() -> Parser:
    parser = Parser(prog="hystkit", description="Hysteresis compensation for lousy "
                    "(3D-printed, soft) sensors.")
    parser.add_argument("--version", action="version", version=f"hystkit {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    package = __name__.rpartition(".")[0]
    for info in sorted(pkgutil.iter_modules(sys.modules[package].__path__), key=lambda m: m.name):
        if info.name.startswith("cmd_"):
            importlib.import_module(f"{package}.{info.name}").register(sub)
    for p in sub.choices.values():
        if not any("--force" in a.option_strings for a in p._actions):
            p.add_argument("--force", action="store_true",
                           help="overwrite existing output files")
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point; returns the exit code (0 success, 2 bad input or divergence)."""
    try:
        args = _parser().parse_args(argv)
        return args.run(args)
    except HystkitError as exc:
        print(f"hystkit: error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        # The reader went away (`hystkit ... | head`): not our error. Point stdout at devnull so
        # the interpreter's final flush does not raise again (Python docs, signal module).
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1


if __name__ == "__main__":
    sys.exit(main())
