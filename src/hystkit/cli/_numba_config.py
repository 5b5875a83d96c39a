"""numba's import in the ``hystkit`` program, without PyYAML when numba has no use for it.

numba's ``numba.core.config`` imports PyYAML (installed here with Dask) only to read a
``.numba_config.yaml`` in the working directory, ~0.01 s of every command that loads a kernel.
The program hides it from that one import when the working directory has no such file (the
program does not change directory, so numba never looks for one it would miss); any other
import of ``yaml`` (Dask's) gets the real module.
"""

from __future__ import annotations

import os
import sys
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from importlib.machinery import ModuleSpec

NUMBA_CONFIG_FILE = ".numba_config.yaml"  # numba's name, read from the working directory
_CONFIG_MODULE = "numba.core.config"


class _YamlHiddenFromNumbaConfig:
    """A meta path finder (a plain class: importlib.abc is not loaded this early in the
    program, ~0.01 s) that refuses ``yaml`` to numba's config module and then has no more to
    say.

    It decides once, at the first import of ``yaml``: refused while numba's config module runs
    (its ``__spec__._initializing``, set by the import system during a module's first run;
    without that attribute nothing is refused), let through otherwise. Either way it is spent
    afterwards; it stays in ``sys.meta_path`` (removing it there during an import would make
    the import system skip the finder after it) and passes every later import on.
    """

    def __init__(self) -> None:
        self.spent = False

    def find_spec(self, name: str, path=None, target=None) -> ModuleSpec | None:
        if self.spent or name != "yaml":
            return None
        self.spent = True
        config = sys.modules.get(_CONFIG_MODULE)
        if config is not None and getattr(config.__spec__, "_initializing", False):
            raise ModuleNotFoundError(f"yaml: hidden from numba's config (no {NUMBA_CONFIG_FILE} "
                                      "in the working directory)", name=name)
        return None


def hide_yaml_from_numba_config() -> None:
    """Install the finder unless numba or yaml is loaded already or numba's config file is
    in the working directory."""
    if _CONFIG_MODULE in sys.modules or "yaml" in sys.modules or os.path.exists(NUMBA_CONFIG_FILE):
        return
    sys.meta_path.insert(0, _YamlHiddenFromNumbaConfig())
