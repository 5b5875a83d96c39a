"""A model fitted without the stability limit (``--no-limit``) is not run live: ``stream``
refuses it in one line before reading any sample (a sample-by-sample run would see its
divergence only after writing wrong estimates)."""

import pytest

from hystkit.cli import main
from hystkit.compensation import fit_compensator, save_compensator
from hystkit.errors import InputError
from hystkit.live import Stream
from hystkit.sensors import simulate_experiment


@pytest.fixture(scope="module")
def unlimited(tmp_path_factory):
    comp = fit_compensator(simulate_experiment("sine", 1), 1, diagnose=False, limit=False)
    return comp, save_compensator(comp, tmp_path_factory.mktemp("free") / "free.json")


def test_the_library_stream_refuses_it(unlimited):
    comp, _ = unlimited
    assert comp.structure.limit is False
    with pytest.raises(InputError, match="structure.limit"):
        Stream(comp)


@pytest.mark.parametrize("adapt", [[], ["--adapt", "gain"], ["--adapt", "full"]])
def test_the_command_refuses_it_in_one_line(unlimited, tmp_path, capsys, adapt):
    _, path = unlimited
    data = tmp_path / "in.csv"
    data.write_text("time,sensor\n0.0,0.1\n0.025,0.2\n")
    assert main(["stream", str(path), "--in", str(data), *adapt]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("hystkit: error: ")
    assert "--no-limit" in lines[0] and "not run live" in lines[0]
