"""Looking up one family by name imports only its folder, and finds what discovery finds.

`hystkit.models._registry`: before anything is discovered or registered, ``get_family(name)``
and ``name in FAMILIES`` import the family's own folder only (``fit --model mpl`` reads no other
family and no entry points). Checked in fresh interpreters, since this test session has long
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
             "from hystkit.models import FAMILIES, get_family\n"
             f"{code}\n")
    return subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                          check=True, timeout=120).stdout.strip()


@pytest.mark.parametrize("name", ["mpl", "mpl-g", "preisach"])
def test_one_name_imports_only_its_own_folder(name):
    out = _fresh(f"family = get_family({name!r})\n"
                 f"assert family.name == {name!r} and {name!r} in FAMILIES\n"
                 f"print(registry._found is None, {_FOLDERS})")
    folder = name.replace("-", "_")
    assert out == f"True ['hystkit.models.{folder}']"


def test_the_same_family_objects_as_discovery():
    """Every name: the lookup's family is the one the full discovery lists."""
    out = _fresh("before = {n: get_family(n) for n in " + repr(sorted(FAMILIES)) + "}\n"
                 "assert registry._found is None\n"
                 "print(all(FAMILIES[n] is f for n, f in before.items()),\n"
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
