"""A subject that leaves the frame and comes back is found again; the detector runs only while there
is no subject (acquiring, or lost). The tracker is started once: it finds the subject again by its
look from the start, and follows it at its size, not on the sliver of it that came into view first."""
from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

import pipelines.loop.track_session
from pipelines.outputs.telemetry import read_telemetry
from tests.track.helpers import BOX, make_clip, out_right_and_back, run_track

BACK_AT = 50  # the frame where the subject starts to come back in from the right


_position = out_right_and_back(BACK_AT, 100)


def test_the_detector_runs_only_without_a_subject_and_finds_it_again(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    calls = {"detect": 0, "init": 0}
    make_detector, make_tracker = pipelines.loop.track_session.make_detector, pipelines.loop.track_session.make_tracker

    def counted(name: str, target: Any) -> Any:
        real = getattr(target, name)

        def call(*args: Any) -> Any:
            calls[name] += 1
            return real(*args)

        setattr(target, name, call)
        return target

    monkeypatch.setattr(pipelines.loop.track_session, "make_detector", lambda *a: counted("detect", make_detector(*a)))
    monkeypatch.setattr(pipelines.loop.track_session, "make_tracker", lambda *a: counted("init", make_tracker(*a)))
    clip = make_clip(tmp_path / "back.avi", 90, _position)
    assert run_track(clip, tmp_path / "out", "--detect", "motion", "--no-video") == 0
    records = read_telemetry(tmp_path / "out" / "telemetry.jsonl")
    states = [r["state"] for r in records]
    lost = states.index("lost")
    assert "tracking" in states[:lost] and lost < BACK_AT
    back = lost + states[lost:].index("tracking")
    assert states[-1] == "tracking" and states[back:].count("tracking") > 0.9 * (len(states) - back), \
        "not found again"
    assert calls["init"] == 1, "started afresh, forgetting the subject's look"
    assert all(r["box"][2] > 0.9 * BOX for r in records[back:])
    # every frame without a subject and the frame whose detection started the tracker; and the frame
    # it was found again in when the detector (or the template search) found it there, not when the
    # tracker's own filter picked it up first (dcf does since it learns from its first 20 frames)
    without_subject = states.count("acquiring") + states.count("lost")
    assert without_subject + 1 <= calls["detect"] <= without_subject + 2
