"""sphinx-gallery hooks of hystkit's site (issue 30): the command-line arguments an example
is run with when the site is built."""

from __future__ import annotations

from pathlib import Path

# The piezo example's full comparison needs the shared data; --excerpt runs it on the excerpts
# that ship with hystkit (the pipeline, in seconds).
ARGUMENTS = {"piezo_micromanipulator.py": ["--excerpt"]}


def reset_argv(gallery_conf: dict, script_vars: dict) -> list[str]:
    """sys.argv[1:] for the example being run."""
    return list(ARGUMENTS.get(Path(script_vars["src_file"]).name, []))
