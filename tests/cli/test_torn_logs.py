"""A CAN log cut short (a recorder killed mid-line, a copy stopped part way) keeps its post-mortem:
``decode`` and ``replay`` warn in one line naming the file and the line, keep every whole frame
before it and print the summary; ``decode -`` reads a log from standard input (a pipe)."""
from __future__ import annotations

import gzip
import json
import select
import subprocess
from pathlib import Path

import can
import pytest

import pipelines.cli.app
from gimbal.client import speed_message
from gimbal.messages import message_packet
from gimbal.packet import encode_packet
from gimbal.transport import packet_frames
from pipelines.cli import main
from tests.support import cli_command, subprocess_env

SPEEDS = [(10.0, 0.0), (20.0, -5.0), (-30.0, 4.0)]


def write_session(path: Path) -> list[str]:
    """A candump log of three speed commands that keep control (as a crashed run leaves it); its lines."""
    with path.open("w") as file:
        writer = can.CanutilsLogWriter(file, channel="can0")
        for i, (yaw, pitch) in enumerate(SPEEDS):
            raw = encode_packet(message_packet(speed_message(yaw, pitch), 100 + i))
            for frame in packet_frames(raw, 0x223):
                frame.timestamp, frame.is_rx = 1000.0 + 0.04 * i, False
                writer.on_message_received(frame)
        writer.stop()
    return path.read_text().splitlines(keepends=True)


def torn_session(tmp_path: Path, keep: int) -> tuple[Path, int]:
    """The session log cut ``keep`` characters into its last line; (path, that line's number)."""
    lines = write_session(tmp_path / "whole.log")
    torn = tmp_path / "torn.log"
    torn.write_text("".join(lines[:-1]) + lines[-1][:keep])
    return torn, len(lines)


@pytest.fixture(autouse=True)
def both_commands(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(pipelines.cli.app, "SUBCOMMAND_MODULES",
                        ["pipelines.cli.decode_cmd", "pipelines.cli.replay_cmd"])


@pytest.mark.parametrize("keep", [27, 20, 9])  # in the data (it would parse), the CAN id, the timestamp
def test_replay_of_a_torn_log_warns_and_prints_its_summary(keep: int, tmp_path: Path,
                                                            capsys: pytest.CaptureFixture[str]) -> None:
    torn, line = torn_session(tmp_path, keep)
    assert main(["replay", str(torn)]) == 0
    out, err = capsys.readouterr()
    assert err == (f"gimbaltrack replay: warning: {torn}: line {line} is cut short (no line end): "
                   "left out, the frames before it are kept\n")
    assert "yaw +20.0 pitch -5.0 deg/s, control HELD" in out  # the last whole speed command
    assert "errors: truncated 1" in out  # the packet the torn line belonged to


def test_a_torn_line_that_would_parse_is_left_out_too(tmp_path: Path,
                                                      capsys: pytest.CaptureFixture[str]) -> None:
    """'223#640044DE' cut from a full frame reads as a shorter frame."""
    lines = write_session(tmp_path / "whole.log")
    torn = tmp_path / "torn.log"
    torn.write_text(lines[0] + lines[1][:lines[1].index("#") + 9])
    assert main(["decode", str(torn)]) == 0
    out, err = capsys.readouterr()
    first = lines[0].split("#")[1].split()[0]
    assert [json.loads(text)["hex"] for text in out.splitlines()] == [bytes.fromhex(first).hex(" ")]
    assert err == (f"gimbaltrack decode: warning: {torn}: line 2 is cut short (no line end): left out, "
                   "the frames before it are kept\n")


def test_a_log_without_one_whole_line_is_unreadable(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    lines = write_session(tmp_path / "whole.log")
    torn = tmp_path / "torn.log"
    torn.write_text(lines[0][:30])
    assert main(["decode", str(torn)]) == 2
    assert capsys.readouterr().err == (f"gimbaltrack decode: error: {torn}: unreadable at its first frame: "
                                       "line 1 is cut short (no line end)\n")


def test_decode_of_a_torn_log_keeps_every_whole_packet(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    torn, line = torn_session(tmp_path, 27)
    assert main(["decode", str(torn)]) == 0
    out, err = capsys.readouterr()
    records = [json.loads(text) for text in out.splitlines()]
    assert [r.get("name", r.get("error")) for r in records] == ["speed_control", "speed_control", "truncated"]
    assert f"{torn}: line {line} is cut short" in err and len(err.splitlines()) == 1


def test_a_compressed_log_cut_short_is_a_warning(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    lines = write_session(tmp_path / "whole.log")
    whole = gzip.compress("".join(lines * 40).encode())
    cut = tmp_path / "cut.log.gz"
    cut.write_bytes(whole[:len(whole) // 2])
    assert main(["replay", str(cut)]) == 0
    out, err = capsys.readouterr()
    assert "the compressed file ends early" in err and len(err.splitlines()) == 1
    assert "last speed command" in out


def test_a_bad_line_mid_log_still_fails_but_the_summary_comes_first(tmp_path: Path,
                                                                    capsys: pytest.CaptureFixture[str]) -> None:
    lines = write_session(tmp_path / "whole.log")
    bad = tmp_path / "bad.log"
    bad.write_text("".join(lines[:8]) + "(1000.1) can0 223#ZZ T\n" + "".join(lines[8:]))  # after 2 packets
    assert main(["replay", str(bad)]) == 2
    out, err = capsys.readouterr()
    assert "last speed command: yaw +20.0 pitch -5.0" in out
    assert err == f"gimbaltrack replay: error: {bad}: unreadable after frame 8: 'ZZ' is not a hexadecimal number\n"


def test_decode_reads_standard_input_through_a_pipe(tmp_path: Path) -> None:
    torn, line = torn_session(tmp_path, 27)
    with torn.open() as log:
        done = subprocess.run(cli_command("decode", "-"), stdin=log, capture_output=True, text=True,
                              env=subprocess_env(), timeout=60)
    assert done.returncode == 0
    assert [json.loads(text).get("name") for text in done.stdout.splitlines()][:2] == ["speed_control"] * 2
    assert done.stderr == (f"gimbaltrack decode: warning: standard input: line {line} is cut short (no line end): "
                           "left out, the frames before it are kept\n")


def test_standard_input_in_another_format(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                          capsys: pytest.CaptureFixture[str]) -> None:
    write_session(tmp_path / "whole.log")
    frames = list(can.LogReader(str(tmp_path / "whole.log")))
    asc = tmp_path / "whole.asc"
    with can.Logger(str(asc)) as writer:
        for frame in frames:
            writer.on_message_received(frame)
    with asc.open() as stdin:
        monkeypatch.setattr("sys.stdin", stdin)
        assert main(["decode", "-", "--format", "asc"]) == 0
    names = [json.loads(text)["name"] for text in capsys.readouterr().out.splitlines()]
    assert names == ["speed_control"] * 3


def test_format_is_for_standard_input_only(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    write_session(tmp_path / "whole.log")
    assert main(["decode", str(tmp_path / "whole.log"), "--format", "asc"]) == 2
    assert capsys.readouterr().err == ("gimbaltrack decode: error: --format applies to - (standard input) "
                                       "only; a file's format comes from its suffix\n")


def test_candump_screen_output_is_named(monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str],
                                        tmp_path: Path) -> None:
    """``candump can0`` without -L prints a layout python-can's .log reader does not read."""
    screen = tmp_path / "screen.txt"
    screen.write_text("  can0  223   [8]  AA 13 00 03 00 00 00 00\n")
    with screen.open() as stdin:
        monkeypatch.setattr("sys.stdin", stdin)
        assert main(["decode", "-"]) == 2
    assert capsys.readouterr().err == (
        "gimbaltrack decode: error: standard input: unreadable at its first frame: this is candump's screen "
        "layout; run candump with -L for its log format\n")


def test_decode_from_a_pipe_shows_each_packet_as_it_arrives(tmp_path: Path) -> None:
    """``candump -L can0 | gimbaltrack decode -``: a packet is printed before the input ends."""
    lines = write_session(tmp_path / "whole.log")
    env = {k: v for k, v in subprocess_env().items() if k != "PYTHONUNBUFFERED"}  # a pipe's usual buffering
    process = subprocess.Popen(cli_command("decode", "-"), stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True, env=env)
    try:
        process.stdin.write("".join(lines[:4]))
        process.stdin.flush()
        assert select.select([process.stdout], [], [], 30)[0], "nothing printed while the input stays open"
        assert json.loads(process.stdout.readline())["name"] == "speed_control"
        process.stdin.close()
        assert process.wait(timeout=60) == 0
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
