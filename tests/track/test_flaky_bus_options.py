"""track's link options: bad values are one line and exit 2, before anything opens."""
from __future__ import annotations

from pathlib import Path

import pytest

from gimbal.sim import Faults
from pipelines.cli.sim_faults import parse_sim_faults
from tests.track.helpers import DEMO, DEMO_ROI, run_track


@pytest.mark.parametrize(("extra", "words"), [
    (("--bus-timeout", "0.5"), "--bus-timeout takes a finite time above 0.5 s"),
    (("--bus-timeout", "nan"), "--bus-timeout takes"),
    (("--sim-faults", "drop=2"), "drop takes a fraction from 0 to 1"),
    (("--sim-faults", "loss=0.2"), "takes KEY=VALUE"),
    (("--sim-faults", "delay-ms=soon"), "delay-ms takes a number"),
    (("--sim-faults", "drop=0.1", "-i", "virtual", "-c", "x"), "--sim-faults is for the built-in simulated gimbal"),
])
def test_bad_link_options_are_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                       extra: tuple[str, ...], words: str) -> None:
    with pytest.raises(SystemExit) as exit_info:
        raise SystemExit(run_track(DEMO, tmp_path / "out", "--roi", DEMO_ROI, *extra))
    assert exit_info.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert words in err[-1] and "Traceback" not in "".join(err)
    assert not (tmp_path / "out").exists()


def test_sim_faults_take_sims_option_names() -> None:
    assert parse_sim_faults("drop=0.2,silent=6:6.3,delay-ms=150,fault-direction=rx,seed=4") == \
        Faults(drop=0.2, silent=(6.0, 6.3), delay_s=0.15, direction="rx", seed=4)
