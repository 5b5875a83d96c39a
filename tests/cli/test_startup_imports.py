"""Building the ``hystkit`` parser loads none of the heavy libraries (issue 11, instant start).

Each subcommand imports what it uses when it runs; option values that need the library (model
family names and sizes, experiment names, centring modes, ...) are computed only when their
subcommand is parsed or its help shown. Checked in a fresh interpreter, since this test
session has long imported everything. No timing here: see benchmarks/bench_startup.py.
"""

from __future__ import annotations

import subprocess
import sys

HEAVY = ("numpy", "numba", "scipy", "pandas", "matplotlib", "control", "pyarrow")


def _loaded_after(code: str) -> list[str]:
    probe = (f"{code}\nimport sys\n"
             f"print(','.join(sorted(m for m in {HEAVY!r} if m in sys.modules)))")
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                         check=True, timeout=120)
    return [m for m in out.stdout.strip().split(",") if m]


def test_building_the_parser_loads_no_heavy_library():
    assert _loaded_after("from hystkit.cli._main import _parser\n_parser()") == []


def test_version_and_top_level_help_load_no_heavy_library():
    for argv in (["--version"], ["--help"]):
        code = ("from hystkit.cli._main import main\n"
                "import contextlib, io\n"
                "with contextlib.redirect_stdout(io.StringIO()):\n"
                "    try:\n"
                f"        main({argv!r})\n"
                "    except SystemExit:\n"
                "        pass")
        assert _loaded_after(code) == [], argv


def test_a_bad_option_is_refused_before_any_heavy_import():
    code = ("from hystkit.cli._main import main\n"
            "import contextlib, io\n"
            "with contextlib.redirect_stderr(io.StringIO()):\n"
            "    assert main(['evaluate', '--no-such-option']) == 2")
    assert _loaded_after(code) == []


def test_subcommand_help_still_names_every_family():
    """The deferred values reach the help text: fit's --model lists the registered families."""
    from hystkit.models import FAMILIES

    out = subprocess.run([sys.executable, "-m", "hystkit", "fit", "--help"],
                         capture_output=True, text=True, check=True, timeout=120).stdout
    for name in FAMILIES:
        assert name in out


def test_the_family_registry_and_metadata_load_no_numba_or_scipy():
    """What ``fit --help`` asks of the families (names, titles, sizes, docs) comes without
    their numba kernels, scipy or pandas: the registry reads each folder's INFO and imports its
    family.py only when the family itself is asked for."""
    code = ("from hystkit.models import FAMILIES, FAMILY_INFO, family_info\n"
            "rows = [(f.name, f.title, f.size_help, f.default_size, f.max_size, f.docs,\n"
            "         f.has_inverse, f.no_inverse_reason)\n"
            "        for f in FAMILY_INFO.values()]\n"
            "assert family_info('mpl').name == 'mpl' and len(rows) == len(FAMILIES)\n"
            "assert all(r[6] == (r[7] == '') for r in rows)  # an inverse unless said why\n"
            "assert sum(r[6] for r in rows) == len(rows) - 1  # all but boucwen")
    assert set(_loaded_after(code)) <= {"numpy"}


def test_a_missing_input_is_refused_before_any_heavy_import():
    """cli._inputs.check_inputs_exist: the instant 'file not found' of a misspelt input."""
    code = ("from hystkit.cli._inputs import check_inputs_exist\n"
            "from hystkit.errors import InputError\n"
            "try:\n"
            "    check_inputs_exist(['no-such-model.json'])\n"
            "except InputError as exc:\n"
            "    assert str(exc) == 'no-such-model.json: file not found'\n"
            "else:\n"
            "    raise AssertionError('no error')")
    assert _loaded_after(code) == []


def test_every_subcommand_help_loads_at_most_numpy():
    """A subcommand's help computes its option values (families, centring modes, modes, ...)
    from light modules only: no numba, scipy, pandas or matplotlib before the work starts."""
    from hystkit.cli._main import _parser

    commands = sorted(_parser()._subparsers._group_actions[0].choices)
    assert {"fit", "control", "pl-search", "stream", "export", "report", "batch"} <= set(commands)
    for command in commands:
        code = ("from hystkit.cli._main import main\n"
                "import contextlib, io\n"
                "with contextlib.redirect_stdout(io.StringIO()):\n"
                "    try:\n"
                f"        main([{command!r}, '--help'])\n"
                "    except SystemExit:\n"
                "        pass")
        assert set(_loaded_after(code)) <= {"numpy"}, command
