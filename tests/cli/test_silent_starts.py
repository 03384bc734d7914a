"""What once sat silent on a terminal (issue #26): a stream with no sender (10 to 20 s while
FFmpeg waits), and ``simulate`` for the whole run. Now a line says what is going on."""
from __future__ import annotations

import functools
from pathlib import Path

import pytest

import pipelines.cli.app
import pipelines.cli.track_cmd
import pipelines.sources.live
from pipelines.cli import main
from pipelines.sources import SourceError, open_source
from tests.support import free_udp_port


@pytest.fixture
def quick_notice(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(pipelines.sources.live, "WAIT_NOTICE_S", 0.3)


def test_a_silent_stream_is_reported_while_it_opens(quick_notice: None) -> None:
    url = f"udp://127.0.0.1:{free_udp_port()}"
    told: list[str] = []
    with pytest.raises(SourceError, match="nothing received within 2 s"):
        open_source(url, open_timeout=2.0, waiting=told.append)
    assert told == [url]


def test_track_says_it_waits_for_a_silent_stream(quick_notice: None, tmp_path: Path,
                                                 monkeypatch: pytest.MonkeyPatch,
                                                 capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setattr(pipelines.cli.app, "SUBCOMMAND_MODULES", ["pipelines.cli.track_cmd"])
    monkeypatch.setattr(pipelines.cli.track_cmd, "open_source", functools.partial(open_source, open_timeout=2.0))
    url = f"udp://127.0.0.1:{free_udp_port()}"
    assert main(["track", url, "--out", str(tmp_path / "out")]) == 2
    assert capsys.readouterr().err.splitlines() == [
        f"gimbaltrack track: waiting for {url}: nothing received yet (Ctrl-C stops)",
        f"gimbaltrack track: error: cannot open stream {url}: nothing received within 2 s"]
    assert main(["track", url, "--out", str(tmp_path / "out"), "--quiet"]) == 2
    assert "waiting for" not in capsys.readouterr().err
