"""``-i sim`` honours --tx-id/--rx-id: the in-process simulator listens and answers on them."""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from pipelines.cli import main


def test_gimbal_on_the_simulator_with_other_ids_answers(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["gimbal", "-i", "sim", "--tx-id", "0x300", "--rx-id", "0x301", "angles", "--json"]) == 0
    angles = json.loads(capsys.readouterr().out)
    assert set(angles) == {"attitude", "joint"} and angles["joint"] == {"yaw": 0.0, "roll": 0.0, "pitch": 0.0}



@pytest.mark.parametrize("command, both", [
    (["gimbal", "-i", "sim", "--tx-id", "0x300", "--rx-id", "0x300", "angles"], "0x300"),
    (["gimbal", "angles", "-i", "sim", "--tx-id", "0x222"], "0x222"),  # the other id's default
    (["track", "samples/demo.mp4", "--roi", "138,152,64,96", "--tx-id", "0x300", "--rx-id", "0x300"], "0x300"),
    (["replay", "LOG", "-i", "sim", "--rx-id", "0x223"], "0x223"),
])
def test_one_id_both_ways_is_refused_like_sim_does(capsys: pytest.CaptureFixture[str], tmp_path: Path,
                                                   command: list[str], both: str) -> None:
    """It once ran and ended in "the gimbal does not answer", exit 1, where ``sim`` refuses it."""
    log, out = tmp_path / "can.log", tmp_path / "out"
    log.write_text("")
    command = [str(log) if arg == "LOG" else arg for arg in command]
    assert main([*command, *(["--out", str(out)] if command[0] == "track" else [])]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].endswith(f": error: --tx-id and --rx-id must differ (both {both})")
    assert not out.exists()
