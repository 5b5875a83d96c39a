"""The ``hystkit`` program loads numba without PyYAML unless numba has a config file to read.

numba imports PyYAML only to read ``.numba_config.yaml`` from the working directory; the
program hides it from that import when there is no such file (~0.01 s of every command that
loads a kernel). Checked in fresh interpreters: numba works, its settings file is still read
where there is one, and every other import of ``yaml`` (Dask's) gets the real module.
"""

from __future__ import annotations

import os
import subprocess
import sys

from hystkit.cli._numba_config import NUMBA_CONFIG_FILE


def _run(call: str, report: str, cwd) -> list[str]:
    code = ("import contextlib, io, sys\n"
            "def _ours():  # the program's finders still to decide\n"
            "    return sum(type(f).__name__ == '_YamlHiddenFromNumbaConfig' and not f.spent\n"
            "               for f in sys.meta_path)\n"
            "from hystkit.cli import main\n"
            "sys.argv = ['hystkit', 'datasets', 'list']\n"
            "with contextlib.redirect_stdout(io.StringIO()):\n"
            f"    assert {call} == 0\n"
            f"{report}")
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_")}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, timeout=300, env=env, cwd=cwd)
    return out.stdout.split()


_AFTER_NUMBA = ("import numba\n"
                "print('yaml' in sys.modules, numba.njit(lambda x: x + 1)(1))\n"
                "import yaml, dask.config\n"
                "print(_ours(), yaml.safe_load('a: 1') == {'a': 1})\n"
                "print(numba.config.CACHE_DIR or '-')\n")


def test_the_program_loads_numba_without_yaml_and_yaml_stays_importable(tmp_path):
    hidden, works, finders, yaml_loads, cache_dir = _run("main()", _AFTER_NUMBA, tmp_path)
    assert (hidden, works) == ("False", "2")  # numba ran a kernel without having loaded yaml
    assert (finders, yaml_loads) == ("0", "True")  # the finder is spent; Dask's yaml is real
    assert cache_dir == "-"


def test_a_numba_config_file_in_the_working_directory_is_still_read(tmp_path):
    (tmp_path / NUMBA_CONFIG_FILE).write_text(f"cache_dir: {tmp_path / 'kernels'}\n")
    loaded, works, finders, _, cache_dir = _run("main()", _AFTER_NUMBA, tmp_path)
    assert (loaded, works, finders) == ("True", "2", "0")
    assert cache_dir == str(tmp_path / "kernels")


def test_an_in_process_call_leaves_numbas_import_alone(tmp_path):
    report = "import numba\nprint('yaml' in sys.modules, _ours())\n"
    assert _run("main(['datasets', 'list'])", report, tmp_path) == ["True", "0"]
