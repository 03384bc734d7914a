"""``gimbaltrack track`` options at their limits (each side of a bound is one line and exit 2), and
the subject's defaults: ``--detect motion`` following the largest mover unless a ``--roi`` is given."""
from __future__ import annotations

from pathlib import Path

import pytest

from pipelines.cli import track_cmd
from pipelines.cli.app import build_parser
from pipelines.track_session import TrackOptions
from tests.track.helpers import DEMO, DEMO_ROI, run_track


@pytest.mark.parametrize("args, words", [
    (["--rate", "51"], "--rate takes 4 to 50 Hz"),
    (["--max-speed", "0"], "--max-speed takes 0 < DEG_S"),
    (["--max-frames", "0"], "--max-frames must be at least 1"),
    (["--video-width", "1"], "--video-width takes 0"),
])
def test_values_just_past_a_bound_are_one_line_errors(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                      args: list[str], words: str) -> None:
    assert run_track(DEMO, tmp_path / "out", "--roi", DEMO_ROI, *args) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("gimbaltrack track: error:") and words in err
    assert not (tmp_path / "out").exists()


def _options(*args: str) -> TrackOptions:
    return track_cmd._options(build_parser().parse_args(["track", "clip.mp4", *args]))


def test_the_subject_defaults_to_the_largest_mover() -> None:
    assert (_options().detect, _options().pick) == ("motion", "largest")
    assert (_options("--detect", "face").detect, _options("--detect", "face").pick) == ("face", "central")
    assert (_options("--roi", "1,2,3,4").detect, _options("--roi", "1,2,3,4").roi) == (None, (1, 2, 3, 4))
    assert _options("--detect", "motion", "--pick", "central").pick == "central"
