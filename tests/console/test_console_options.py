"""``track --console`` and ``--console-token``: bad values, and a port already taken, are one line
and exit 2 before the output folder exists; a token given is the one printed and required."""
from __future__ import annotations

import socket
from pathlib import Path

import pytest

from tests.console.http_helpers import post, request
from tests.console.track_run import ConsoleRun
from tests.track.helpers import DEMO, DEMO_ROI, run_track


def _refused(tmp_path: Path, capsys: pytest.CaptureFixture[str], *extra: str) -> str:
    with pytest.raises(SystemExit) as exit_info:
        raise SystemExit(run_track(DEMO, tmp_path / "out", "--roi", DEMO_ROI, "--no-video", *extra))
    assert exit_info.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert "Traceback" not in "".join(err) and len(err) == 1, err
    assert not (tmp_path / "out").exists()
    return err[0]


@pytest.mark.parametrize(("extra", "words"), [
    (("--console", "nothost:abc"), "--console takes [HOST:]PORT with a port number, not 'nothost:abc'"),
    (("--console", "127.0.0.1:99999"), "--console port must be 0 to 65535"),
    (("--console-token", "abcdefghij"), "--console-token needs --console"),
    (("--console", "0", "--console-token", "short"), "--console-token must be at least 8 characters"),
])
def test_bad_console_options_are_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                          extra: tuple[str, ...], words: str) -> None:
    assert words in _refused(tmp_path, capsys, *extra)


def test_a_console_port_in_use_is_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        line = _refused(tmp_path, capsys, "--console", str(port))
    assert f"cannot serve the console on 127.0.0.1:{port}" in line


def test_a_token_given_is_printed_and_required(tmp_path: Path) -> None:
    token = "given-token-123"
    run = ConsoleRun(tmp_path, "--console-token", token, console="0.0.0.0:0")
    try:
        assert run.url.endswith(f"/?token={token}")
        assert request(run.port, "GET", "/api/state")[0] == 401
        assert request(run.port, "GET", "/api/state", headers={"Authorization": "Bearer another-token"})[0] == 401
        assert request(run.port, "GET", f"/api/state?token={token}")[0] == 200
        assert post(run.port, "/api/stop", {}, headers={"Authorization": f"Bearer {token}"})[0] == 200
        code, _, stderr = run.finish()
    finally:
        run.kill()
    assert code == 0, stderr
