"""``-i sim`` honours --tx-id/--rx-id: the in-process simulator listens and answers on them."""
from __future__ import annotations

import json

import pytest

from pipelines.cli import main


def test_gimbal_on_the_simulator_with_other_ids_answers(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["gimbal", "-i", "sim", "--tx-id", "0x300", "--rx-id", "0x301", "angles", "--json"]) == 0
    angles = json.loads(capsys.readouterr().out)
    assert set(angles) == {"attitude", "joint"} and angles["joint"] == {"yaw": 0.0, "roll": 0.0, "pitch": 0.0}
