"""``gimbaltrack replay``: a track session's can.log decoded, summarised and played onto a bus."""
from __future__ import annotations

import json
import struct
import threading
import time
import uuid
from pathlib import Path

import can
import pytest

from gimbal.packet import Packet, encode_packet
from gimbal.transport import packet_frames
from pipelines.cli import main
from tests.track.helpers import decoded, make_clip, roi_at, run_track, speed_commands


def _position(i: int) -> tuple[int, int]:
    return 230 + i % 3, 60  # right of and above the centre


@pytest.fixture(scope="module")
def session_log(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("replay")
    clip = make_clip(root / "clip.avi", 30, _position)
    assert run_track(clip, root / "out", "--roi", roi_at(_position), "--no-video", "--realtime") == 0
    return root / "out" / "can.log"


def test_readable_lines_and_summary(session_log: Path, capsys: pytest.CaptureFixture[str]) -> None:
    capsys.readouterr()
    assert main(["replay", str(session_log)]) == 0
    lines = capsys.readouterr().out.splitlines()
    records = decoded(session_log)
    packet_lines, summary = lines[:len(records)], "\n".join(lines[len(records):])
    assert sum("speed_control " in line for line in packet_lines) == len(speed_commands(records))
    assert not any("ERROR" in line for line in packet_lines)
    moving = next(line for line in packet_lines if "speed_control " in line and "yaw=+" in line
                  and "yaw=+0.0" not in line)
    assert "deg/s" in moving and "pitch=+" in moving and "ctrl=0x88" in moving
    assert f"speed commands: {len(speed_commands(records))} at " in summary
    assert "errors: none" in summary and "control released" in summary


def test_json_lines_end_with_the_summary(session_log: Path, capsys: pytest.CaptureFixture[str]) -> None:
    capsys.readouterr()
    assert main(["replay", str(session_log), "--json"]) == 0
    objects = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    summary = objects[-1]["summary"]
    speeds = speed_commands(decoded(session_log))
    assert objects[:-1] == decoded(session_log)
    assert summary["speed_commands"] == len(speeds) and summary["errors"] == {}
    assert summary["max_speed_dps"] == max(max(abs(c.yaw), abs(c.pitch)) for c in speeds)
    assert 10 <= summary["speed_rate_hz"] <= 2 * 25 * 1.05
    assert summary["last_speed"]["released"] is True


def test_onto_the_simulator(session_log: Path, capsys: pytest.CaptureFixture[str]) -> None:
    capsys.readouterr()
    assert main(["replay", str(session_log), "--json", "-i", "sim", "--speed", "4"]) == 0
    objects = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    state = objects[-2]["sim_state"]
    assert objects[-1]["summary"]["frames_sent"] > 0  # the summary stays last, as without -i sim
    assert state["speeds"] == [0.0, 0.0, 0.0] and not state["speed_control"]
    assert state["joint"][0] > 1.0 and state["joint"][2] > 1.0  # it turned right and up


def test_onto_a_bus_at_the_recorded_pace(session_log: Path, capsys: pytest.CaptureFixture[str]) -> None:
    channel = f"replay-{uuid.uuid4().hex}"
    received: list[can.Message] = []
    with can.Bus(interface="virtual", channel=channel) as listener:
        done = threading.Event()

        def collect() -> None:
            while not done.is_set():
                if (msg := listener.recv(0.05)) is not None:
                    received.append(msg)

        thread = threading.Thread(target=collect)
        thread.start()
        started = time.monotonic()
        try:
            assert main(["replay", str(session_log), "-i", "virtual", "-c", channel, "--speed", "2"]) == 0
        finally:
            elapsed = time.monotonic() - started
            time.sleep(0.1)
            done.set()
            thread.join()
    frames = [f for f in can.LogReader(str(session_log)) if f.arbitration_id == 0x223 and not f.is_rx]
    assert [bytes(m.data) for m in received] == [bytes(f.data) for f in frames]
    assert all(m.arbitration_id == 0x223 for m in received)
    assert elapsed >= 0.8 * (frames[-1].timestamp - frames[0].timestamp) / 2  # timestamps honoured


@pytest.mark.parametrize("content, words", [(None, "no such file"), (b"not a log\n", "unreadable"),
                                            (b"\x00\x01", "unreadable")])
def test_bad_files(tmp_path: Path, capsys: pytest.CaptureFixture[str], content: bytes | None,
                   words: str) -> None:
    path = tmp_path / "bad.log"
    if content is not None:
        path.write_bytes(content)
    assert main(["replay", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("gimbaltrack replay: error:") and words in err


def test_onto_a_bus_only_whole_in_range_packets_go_out(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A foreign log: out-of-range speeds, a command the document does not define and a packet cut
    short are decoded and reported, but never sent to a gimbal."""
    def speed(yaw: int, ctrl: int, seq: int) -> bytes:
        return encode_packet(Packet.command(0x0E, 0x01, struct.pack("<hhhB", yaw, 0, 0, ctrl), seq))

    packets = [speed(300, 0x88, 1), speed(5000, 0x88, 2), speed(-32768, 0x88, 3),
               encode_packet(Packet.command(0x0E, 0x7F, b"\x00", 4)), speed(0, 0x08, 5), speed(200, 0x88, 6)[:12]]
    log = tmp_path / "foreign.log"
    with log.open("w") as file:
        writer = can.CanutilsLogWriter(file, channel="can0")
        for i, raw in enumerate(packets):
            for frame in packet_frames(raw, 0x223):
                frame.timestamp, frame.is_rx = 1000.0 + 0.01 * i, False
                writer.on_message_received(frame)
        writer.stop()
    channel = f"replay-{uuid.uuid4().hex}"
    with can.Bus(interface="virtual", channel=channel) as listener:
        assert main(["replay", str(log), "-i", "virtual", "-c", channel, "--json"]) == 0
        received = b"".join(bytes(m.data) for m in iter(lambda: listener.recv(0.2), None))
    assert received == packets[0] + packets[4]
    summary = json.loads(capsys.readouterr().out.strip().splitlines()[-1])["summary"]
    assert summary["packets_not_sent"] == {"out_of_range": 2, "undecodable": 1, "truncated": 1}


@pytest.mark.parametrize("argv, words", [(["--speed", "inf"], "finite factor"), (["-c", "can0"], "need -i")])
def test_bad_options_are_one_line_errors(session_log: Path, capsys: pytest.CaptureFixture[str], argv: list[str],
                                         words: str) -> None:
    assert main(["replay", str(session_log), *argv]) == 2
    err = capsys.readouterr().err
    assert err.startswith("gimbaltrack replay: error:") and words in err and err.count("\n") == 1
