"""Looking up one family by name imports only its folder, and finds what discovery finds.

`hystkit.models._registry`: before anything is discovered or registered, ``family_info(name)``
and ``name in FAMILIES`` import the family's own folder only (its light ``INFO``), and
``get_family(name)`` adds its ``family.py`` and what that imports (``fit --model mpl`` reads no
other family and no entry points). Checked in fresh interpreters, since this test session has long
discovered every family.
"""

from __future__ import annotations

import copy
import subprocess
import sys

import pytest

from hystkit.errors import InputError
from hystkit.models import FAMILIES, get_family, register, unregister

# The family folders (sub-packages) imported so far.
_FOLDERS = ("sorted(m for m in sys.modules if m.startswith('hystkit.models.')\n"
            "       and m.count('.') == 2 and not m.rpartition('.')[2].startswith('_'))")


def _fresh(code: str) -> str:
    probe = ("import sys\nimport hystkit.models._registry as registry\n"
             "from hystkit.models import FAMILIES, family_info, get_family\n"
             f"{code}\n")
    return subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                          check=True, timeout=120).stdout.strip()


@pytest.mark.parametrize("name", ["mpl", "mpl-g", "preisach"])
def test_one_name_imports_only_its_own_folder(name):
    """Its INFO from its folder's light ``__init__``; no discovery, no other family."""
    out = _fresh(f"info = family_info({name!r})\n"
                 f"assert info.name == {name!r} and {name!r} in FAMILIES\n"
                 f"print(registry._found is None, 'numba' in sys.modules, {_FOLDERS})")
    folder = name.replace("-", "_")
    assert out == f"True False ['hystkit.models.{folder}']"


@pytest.mark.parametrize("name", ["mpl", "mpl-g", "preisach"])
def test_the_family_loads_its_own_code_only(name):
    """``get_family`` imports the folder's family.py and what it imports (mpl-g reuses the mPL
    cells and mpl-poly's output resistor), nothing else: no discovery, no other family."""
    folder = name.replace("-", "_")
    alone = _fresh(f"import hystkit.models.{folder}.family\nprint({_FOLDERS})")
    out = _fresh(f"family = get_family({name!r})\n"
                 f"assert family.name == {name!r} and family is FAMILIES[{name!r}]\n"
                 f"print(registry._found is None, {_FOLDERS})")
    assert out == f"True {alone}" and f"'hystkit.models.{folder}'" in alone


def test_the_same_family_objects_as_discovery():
    """Every name: the lookup's family and record are the ones the full discovery lists."""
    out = _fresh("before = {n: get_family(n) for n in " + repr(sorted(FAMILIES)) + "}\n"
                 "assert registry._found is None\n"
                 "from hystkit.models import FAMILY_INFO, FamilyInfo\n"
                 "print(all(FAMILIES[n] is f and FAMILY_INFO[n] == FamilyInfo.of(f)\n"
                 "          for n, f in before.items()),\n"
                 "      sorted(FAMILIES) == sorted(before), registry._found is not None)")
    assert out == "True True True"


def test_an_unknown_name_lists_every_family():
    assert "nope" not in FAMILIES and "_registry" not in FAMILIES and "mpl.fit" not in FAMILIES
    with pytest.raises(InputError) as err:
        get_family("nope")
    assert str(err.value) == (f"unknown model 'nope'; known models: "
                              f"{', '.join(sorted(FAMILIES))}")
    with pytest.raises(KeyError):
        FAMILIES["nope"]


def test_a_registered_family_replaces_the_folders_one():
    original = get_family("pl")
    stand_in = copy.copy(original)  # another object of the same name
    register(stand_in)
    try:
        assert get_family("pl") is stand_in and FAMILIES["pl"] is stand_in
    finally:
        register(original)
    assert get_family("pl") is original


def test_unregister_then_lookup_does_not_bring_a_folder_family_back_silently():
    """After a discovery, the registry is what it holds: an unregistered name is unknown."""
    original = get_family("ladder")
    unregister("ladder")
    try:
        assert "ladder" not in FAMILIES
    finally:
        register(original)
    assert FAMILIES["ladder"] is original
