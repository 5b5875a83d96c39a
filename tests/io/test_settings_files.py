"""Both kinds of settings file (a raw recording's, a recording's) are found by one rule and read
by one loader, whose failures are one line naming the file (issue 28: one helper for both)."""

from __future__ import annotations

import re

import pytest

from hystkit.errors import InputError
from hystkit.io import (
    find_raw_config,
    find_recording_config,
    read_raw_config,
    read_recording_config,
)


@pytest.mark.parametrize("find", [find_raw_config, find_recording_config])
def test_the_settings_beside_a_file_have_its_stem(tmp_path, find):
    data = tmp_path / "run1.parquet"
    assert find(data) is None
    (tmp_path / "run1.toml").write_text('time_unit = "ms"\n', encoding="utf-8")
    assert find(data) == tmp_path / "run1.toml"
    assert find(tmp_path / "run2.csv") is None
    (tmp_path / "run2.toml").mkdir()  # a folder is no settings file
    assert find(tmp_path / "run2.csv") is None


@pytest.mark.parametrize(("read", "what"), [(read_raw_config, "config file"),
                                            (read_recording_config, "settings file")])
def test_a_settings_file_that_cannot_be_read_is_named_in_one_line(tmp_path, read, what):
    missing = tmp_path / "none.toml"
    with pytest.raises(InputError, match=f"^{re.escape(str(missing))}: {what} not found$"):
        read(missing)
    folder = tmp_path / "folder.toml"
    folder.mkdir()
    with pytest.raises(InputError,
                       match=f"^{re.escape(str(folder))}: is a folder, not a TOML settings file$"):
        read(folder)
    broken = tmp_path / "broken.toml"
    broken.write_text("time_unit = \n", encoding="utf-8")
    with pytest.raises(InputError, match=rf"^{re.escape(str(broken))}: invalid TOML \(.*\)$"):
        read(broken)
    latin = tmp_path / "latin.toml"
    latin.write_bytes(b'time_unit = "\xb5s"\n')  # Latin-1, not UTF-8
    with pytest.raises(InputError,
                       match=rf"^{re.escape(str(latin))}: cannot read {what} \(.*\)$"):
        read(latin)


@pytest.mark.parametrize("read", [read_raw_config, read_recording_config])
def test_a_byte_order_mark_is_read_past(tmp_path, read):
    path = tmp_path / "bom.toml"
    path.write_bytes(b'\xef\xbb\xbftime_unit = "ms"\n')
    assert read(path) == {"time_unit": "ms"}
