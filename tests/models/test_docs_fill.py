"""The shared docstring entries (``hystkit.models._docs``): filled in where a line asks for them,
indented as that line, for the family's record types; none left unfilled in any model module."""

from __future__ import annotations

import importlib
import inspect
import pkgutil

import pytest

import hystkit.models
from hystkit.models._docs import ENTRIES, docfiller, filled

DOC = """Summary.

    Parameters
    ----------
    %(structure)s
    x : float
        Something else, 50 %(not a key) kept.
    """


def test_an_entry_is_filled_in_indented_for_the_record_types() -> None:
    text = filled(DOC, "PlStructure", "PlParams")
    assert text.splitlines()[4:8] == ["    structure : PlStructure",
                                      "        The model's structure.",
                                      "    params : PlParams",
                                      "        Its parameters."]
    assert "50 %(not a key) kept." in text  # only whole lines are entries


def test_the_state_entry_is_the_modules_own() -> None:
    @docfiller("MplStructure", "MplParams", state="x_cells")
    def step(structure, params, x, u):
        """One sample.

        %(step)s
        """

    # indented as the %(step)s line (8 spaces inside this test function)
    assert ("        x : numpy.ndarray, shape (N,)\n            Cell voltages before the sample."
            in step.__doc__)
    assert "%(" not in step.__doc__


def test_an_unknown_entry_fails_at_import_time() -> None:
    with pytest.raises(KeyError):
        filled("Summary.\n\n    %(no_such_entry)s\n")
    assert "no_such_entry" not in ENTRIES


def _documented_objects():
    for info in pkgutil.walk_packages(hystkit.models.__path__, "hystkit.models."):
        module = importlib.import_module(info.name)
        for name, obj in vars(module).items():
            if getattr(obj, "__module__", None) != info.name:
                continue
            if inspect.isfunction(obj) or inspect.isclass(obj):
                yield f"{info.name}.{name}", obj
                if inspect.isclass(obj):
                    for attr, member in vars(obj).items():
                        if inspect.isfunction(member):
                            yield f"{info.name}.{name}.{attr}", member


def test_no_model_docstring_is_left_unfilled() -> None:
    left = [name for name, obj in _documented_objects()
            if obj.__doc__ and "%(" in obj.__doc__ and not name.startswith("hystkit.models._docs")]
    assert not left, left
