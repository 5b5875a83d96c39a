"""Names used across packages are public: the CLI, reports, compensation and metrics modules
import other packages only through their ``__init__``, never a private module."""

import ast
from pathlib import Path

import pytest

import hystkit
import hystkit.compensation
import hystkit.studies

SRC = Path(hystkit.__file__).parent
CHECKED = [SRC / "cli" / "cmd_core.py", SRC / "cli" / "cmd_compare.py",
           SRC / "cli" / "cmd_select.py", *sorted((SRC / "studies").glob("*.py")),
           *sorted((SRC / "compensation").glob("*.py")), *sorted((SRC / "metrics").glob("*.py"))]


def _private_imports_across_packages(path: Path) -> list[str]:
    found = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            parts = (node.module or "").split(".")
            crosses = node.level >= 2 or (node.level == 0 and parts[0] == "hystkit")
            # hystkit's own top-level helpers (hystkit._lazy) belong to no other package
            root_helper = (node.level == 2 and len(parts) == 1) or (
                node.level == 0 and len(parts) == 2 and parts[0] == "hystkit")
            if crosses and not root_helper and any(part.startswith("_") for part in parts):
                found.append(f"{path.name}:{node.lineno}: {'.' * node.level}{node.module}")
    return found


@pytest.mark.parametrize("path", CHECKED, ids=lambda p: f"{p.parent.name}/{p.name}")
def test_no_private_module_of_another_package_is_imported(path):
    assert _private_imports_across_packages(path) == []


def test_the_checker_sees_a_private_import(tmp_path):
    probe = tmp_path / "probe.py"
    probe.write_text("from ..compensation._compensator import POSITION_MARGIN\n"
                     "from hystkit.studies._select import folds\n"
                     "from ._x import y\nfrom ..compensation import evaluate\n"
                     "from .._lazy import lazy_exports\n")
    assert _private_imports_across_packages(probe) == [
        "probe.py:1: ..compensation._compensator", "probe.py:2: hystkit.studies._select"]


@pytest.mark.parametrize(("package", "names"), [
    (hystkit.compensation, ["DEFAULT_TARE_SECONDS", "DEFAULT_TRACK_SECONDS", "POSITION_MARGIN",
                            "SENSOR_MARGIN", "use_flags", "centre_and_scale"]),
    (hystkit.studies, ["compare_models", "format_compare", "generalization_matrix",
                       "plot_generalization", "candidates", "plot_selection", "select_model"]),
])
def test_the_names_are_exported(package, names):
    assert set(names) <= set(package.__all__)
    assert all(getattr(package, name) is not None for name in names)
