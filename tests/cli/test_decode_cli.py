"""``gimbaltrack decode``: hex and log input, JSON lines out, one-line errors with exit 2."""
from __future__ import annotations

import json
from pathlib import Path

import can
import pytest

from gimbal.messages import message_packet
from gimbal.messages.motion import AnglesReply, GetAngles
from gimbal.packet import encode_packet
from gimbal.transport import packet_frames
import pipelines.cli.app
from pipelines.cli import main

DOC_EXAMPLE = "AA 1A 00 03 00 00 00 00 22 11 A2 42 0E 00 20 00 30 00 40 00 01 14 7B 40 97 BE"


@pytest.fixture(autouse=True)
def only_decode(monkeypatch: pytest.MonkeyPatch) -> None:
    """The real dispatcher, with only this subcommand (others' modules are not under test here)."""
    monkeypatch.setattr(pipelines.cli.app, "SUBCOMMAND_MODULES", ["pipelines.cli.decode_cmd"])


def run(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, list[dict], str]:
    code = main(["decode", *argv])
    out, err = capsys.readouterr()
    return code, [json.loads(line) for line in out.splitlines()], err


def test_document_example(capsys: pytest.CaptureFixture[str]) -> None:
    code, records, err = run(["--hex", DOC_EXAMPLE], capsys)
    assert code == 0 and err == ""
    assert records == [{
        "direction": "host->gimbal", "timestamp": None, "seq": 0x1122, "cmd_type": 3, "is_reply": False,
        "cmd_set": 0x0E, "cmd_id": 0x00, "name": "position_control", "kind": "command",
        "fields": {"yaw_angle": 32, "roll_angle": 48, "pitch_angle": 64, "ctrl_byte": 1, "time_for_action": 20},
        "hex": DOC_EXAMPLE.lower()}]


def test_several_packets_spaces_optional_and_legacy_reply_matched(capsys: pytest.CaptureFixture[str]) -> None:
    request = encode_packet(message_packet(GetAngles(1), 7)).hex()
    reply = encode_packet(message_packet(AnglesReply(0, 1, 10, 20, 30), 7, legacy=True)).hex(":")
    code, records, _ = run(["--hex", request + reply.upper()], capsys)
    assert code == 0
    assert [r["direction"] for r in records] == ["host->gimbal", "gimbal->host"]
    assert records[1]["name"] == "get_angles_reply" and records[1]["layout"] == "legacy"


def test_forced_direction_and_bad_bytes_still_exit_0(capsys: pytest.CaptureFixture[str]) -> None:
    code, records, _ = run(["--hex", "00 11 " + DOC_EXAMPLE[:20], "--direction", "gimbal"], capsys)
    assert code == 0
    assert [r["error"] for r in records] == ["garbage", "truncated"]
    assert {r["direction"] for r in records} == {"gimbal->host"}


@pytest.mark.parametrize("argv,message", [
    (["--hex", "AA 1"], "odd number"),
    (["--hex", "AG"], "not a hex digit"),
    (["/no/such/file.log"], "no such file"),
])
def test_unreadable_input_is_one_line_exit_2(argv: list[str], message: str,
                                             capsys: pytest.CaptureFixture[str]) -> None:
    code, records, err = run(argv, capsys)
    assert code == 2 and records == []
    assert message in err and len(err.strip().splitlines()) == 1 and "Traceback" not in err


def test_unknown_format_and_corrupt_log(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    unknown = tmp_path / "capture.xyz"
    unknown.write_text("hello")
    corrupt = tmp_path / "capture.blf"
    corrupt.write_bytes(b"not a blf file at all" * 4)
    for path in (unknown, corrupt, tmp_path):
        code, _, err = run([str(path)], capsys)
        assert code == 2 and len(err.strip().splitlines()) == 1, err


@pytest.mark.parametrize("name, text, message", [
    ("hex.log", "(1.0) can0 223#0011\n(2.0) can0 223#ZZ\n", "unreadable after frame 1: 'ZZ' is not a hexadecimal number"),
    ("fields.log", "garbage\n", "unreadable at its first frame: a line has too few or too many fields for this format"),
    ("time.log", "(x) can0 223#00\n", "unreadable at its first frame: 'x' is not a number"),
    ("base64.csv", "timestamp,arbitration_id,extended,remote,error,dlc,data\n1.0,0x223,0,0,0,1,ZZ\n",
     "unreadable at its first frame: its data is not valid base64"),
])
def test_a_malformed_log_line_is_worded_for_a_user(name: str, text: str, message: str, tmp_path: Path,
                                                  capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / name
    path.write_text(text)
    code, _, err = run([str(path)], capsys)
    assert code == 2 and err == f"gimbaltrack decode: error: {path}: {message}\n"


def test_direction_refused_for_logs(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "empty.log"
    path.write_text("")
    assert run([str(path), "--direction", "host"], capsys)[0] == 2


def test_candump_log_with_ids(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "capture.log"
    raw = bytes.fromhex(DOC_EXAMPLE)
    lines = [f"(1.{i:06d}) can0 {0x301:03X}#{bytes(f.data).hex().upper()}"
             for i, f in enumerate(packet_frames(raw, 0x301))]
    lines.insert(1, "(1.000500) can0 530#55AA0102")
    path.write_text("\n".join(lines) + "\n")
    code, records, _ = run([str(path), "--tx-id", "0x301", "--rx-id", "0x302"], capsys)
    assert code == 0 and [r["name"] for r in records] == ["position_control"]
    assert records[0]["timestamp"] == pytest.approx(1.000003)
    code, records, _ = run([str(path)], capsys)  # default ids: nothing of ours on the bus
    assert code == 0 and records == []


def test_log_of_garbage_exits_0(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "noise.asc"
    with can.Logger(str(path)) as writer:
        for i in range(5):
            writer.on_message_received(can.Message(arbitration_id=0x222, data=bytes([i, 0xAA, 0x01]),
                                                   is_extended_id=False, timestamp=float(i), channel=0))
    code, records, _ = run([str(path)], capsys)
    assert code == 0 and records and all("error" in r for r in records)


@pytest.mark.parametrize("command", ["decode", "replay"])
def test_a_log_without_frames_is_a_note_and_exit_0(command: str, tmp_path: Path,
                                                   capsys: pytest.CaptureFixture[str],
                                                   monkeypatch: pytest.MonkeyPatch) -> None:
    """decode and replay read logs through the same LogFrames."""
    monkeypatch.setattr(pipelines.cli.app, "SUBCOMMAND_MODULES", [f"pipelines.cli.{command}_cmd"])
    path = tmp_path / "empty.log"
    path.write_text("")
    assert main([command, str(path)]) == 0
    err = capsys.readouterr().err
    assert err == f"gimbaltrack {command}: note: {path} holds no CAN frames\n"
