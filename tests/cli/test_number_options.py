"""Numbers on the command line that were a traceback, a wait for ever or silence (issue #26):
each is now one line naming the option and its range, exit 2, and nothing opened or written."""
from __future__ import annotations

from pathlib import Path

import pytest

import pipelines.cli.app
from gimbal.client import position_message, speed_message
from gimbal.errors import RangeError
from pipelines.cli import main
from tests.track.helpers import DEMO


@pytest.fixture(autouse=True)
def commands(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(pipelines.cli.app, "SUBCOMMAND_MODULES", [
        "pipelines.cli.gimbal_cmd", "pipelines.cli.replay_cmd", "pipelines.cli.track_cmd",
        "pipelines.cli.decode_cmd"])


def one_line_error(capsys: pytest.CaptureFixture[str]) -> str:
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    return err.rstrip("\n")


@pytest.mark.parametrize("argv, message", [
    (["move", "--yaw", "1e308"], "--yaw 1e+308 is outside the document's -180..180°"),
    (["move", "--pitch=-1e308"], "--pitch -1e+308 is outside the document's -56..146°"),
    (["move", "--roll", "31"], "--roll: position_control.roll_angle=310 is outside -300..300 (31°: allowed -30..30°)"),
    (["move", "--yaw", "1", "--time", "1e308"], "--time 1e+308 is outside the document's 0..25.5 s"),
    (["move", "--yaw", "1", "--time", "-1"],
     "--time: position_control.time_for_action=-10 is outside 0..255 (-1 s: allowed 0..25.5 s)"),
    (["speed", "--yaw", "1e308"], "--yaw 1e+308 is outside the document's -360..360°/s"),
    (["speed", "--pitch", "-361"],
     "--pitch: speed_control.pitch_speed=-3610 is outside -3600..3600 (-361°/s: allowed -360..360°/s)"),
    (["speed", "--roll", "nan"], "--roll nan is outside the document's -360..360°/s"),
])
@pytest.mark.parametrize("where", [["--print-packet"], ["-i", "sim"]])
def test_gimbal_numbers_outside_the_document_are_one_line(argv: list[str], message: str, where: list[str],
                                                          capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["gimbal", *argv, *where]) == 2
    assert one_line_error(capsys) == f"gimbaltrack gimbal: error: {message}"


def test_the_library_refuses_huge_numbers_as_a_range_error() -> None:
    """round(1e308 * 10) was an OverflowError, which no caller expected."""
    with pytest.raises(RangeError, match=r"yaw angle=1e\+308 is outside"):
        position_message(1e308)
    with pytest.raises(RangeError, match=r"pitch speed=-1e\+308 is outside"):
        speed_message(0.0, -1e308)


def test_huge_numbers_are_shown_compactly(capsys: pytest.CaptureFixture[str]) -> None:
    from gimbal.values import shown
    assert shown(10 ** 301) == "1e+301" and shown(-(10 ** 40) - 7) == "-1e+40"
    assert shown(1e308) == "1e+308" and shown(123456789) == "123456789" and shown(2.5) == "2.5"
    assert shown("x") == "'x'" and shown(True) == "True"
    assert main(["gimbal", "joystick", "--yaw", "9" * 300, "--print-packet"]) == 2
    err = one_line_error(capsys)
    assert "1e+300" in err and len(err) < 200, err


def test_the_limits_below_zero_are_shown_and_taken_signed(capsys: pytest.CaptureFixture[str]) -> None:
    """The document's pitch_min 0..55 is how far below zero the limit is: -55 degrees."""
    assert main(["gimbal", "limits", "-i", "sim"]) == 0
    assert capsys.readouterr().out == ("limits: pitch_max 145  pitch_min -55  yaw_max 179  yaw_min -179  "
                                       "roll_max 30  roll_min -30\n")
    assert main(["gimbal", "limits", "--pitch-max", "90", "--pitch-min", "-30", "--yaw-max", "120",
                 "--yaw-min", "-100", "--roll-max", "20", "--roll-min", "-10", "--print-packet"]) == 0
    # on the wire the magnitudes, as the document encodes them: 90, 30, 120, 100, 20, 10
    assert " 01 5A 1E 78 64 14 0A " in capsys.readouterr().out
    assert main(["gimbal", "limits", "--pitch-min", "30", "--print-packet"]) == 2
    assert one_line_error(capsys) == ("gimbaltrack gimbal: error: --pitch-min 30 is outside the document's "
                                      "-55..0° (a limit below zero)")
    assert main(["gimbal", "limits", "--yaw-max", "180", "-i", "sim"]) == 2
    assert one_line_error(capsys) == "gimbaltrack gimbal: error: --yaw-max 180 is outside the document's 0..179°"


@pytest.mark.parametrize("speed", ["1e-15", "1e-10", "0.05", "101", "1e308"])
def test_replay_speed_is_bounded(speed: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    log = tmp_path / "one.log"
    log.write_text("(0.0) can0 223#AA1A000300000000\n(1000000.0) can0 223#AA1A000300000000\n")
    assert main(["replay", str(log), "--realtime", "--speed", speed]) == 2
    assert one_line_error(capsys) == (f"gimbaltrack replay: error: --speed takes a finite factor from 0.1 to 100, "
                                      f"not {float(speed):g}")


@pytest.mark.parametrize("fps", ["0.001", "65536", "0.05", "1001"])
def test_track_fps_outside_its_range_opens_nothing(fps: str, tmp_path: Path,
                                                  capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "out"
    assert main(["track", str(DEMO), "--fps", fps, "--out", str(out)]) == 2
    assert one_line_error(capsys) == (f"gimbaltrack track: error: --fps takes 0.1 to 1000 frames a second, "
                                      f"not {float(fps):g}")
    assert not out.exists()


@pytest.mark.parametrize("hex_args", [[""], ["  "], ["AA", ""], [": ,"]])
def test_decode_hex_without_bytes_is_an_error(hex_args: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    argv = [item for text in hex_args for item in ("--hex", text)]
    assert main(["decode", *argv]) == 2
    assert one_line_error(capsys) == "gimbaltrack decode: error: --hex: no hex digits in an argument"
