"""The control tests keep the sensor models and loop margins they compute in one temporary
cache folder per session (hystkit.control's disk cache): the first test that needs the CLI's
default models fits them, the others read them, and nothing is written to the user's cache."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="session", autouse=True)
def _cache_folder(tmp_path_factory):
    folder = tmp_path_factory.mktemp("hystkit-cache")
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("HYSTKIT_CACHE_DIR", str(folder))  # also for the commands' subprocesses
        yield folder
