"""CanTransport over python-can's virtual bus: whole packets, no interleaving, foreign ids ignored."""
from __future__ import annotations

import itertools
import json
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import can
import pytest

from gimbal.client import GimbalClient
from gimbal.errors import BusError
from gimbal.framer import Dropped
from gimbal.messages import message_packet
from gimbal.messages.motion import AnglesReply, SpeedControl
from gimbal.messages.telemetry import ParameterPush
from gimbal.packet import Packet, decode_packet, encode_packet
from gimbal.transport import CanTransport, packet_frames, with_default_bitrate


_channels = itertools.count()


class YieldingBus(can.BusABC):
    """A virtual bus that gives up the GIL after every frame, so unguarded senders interleave."""

    def __init__(self, channel: str) -> None:
        self._inner = can.Bus(interface="virtual", channel=channel)
        super().__init__(channel=channel)

    def send(self, msg: can.Message, timeout: float | None = None) -> None:
        self._inner.send(msg, timeout)
        time.sleep(0)

    def _recv_internal(self, timeout: float | None) -> tuple[can.Message | None, bool]:
        return self._inner.recv(timeout), False

    def shutdown(self) -> None:
        self._inner.shutdown()
        super().shutdown()


@pytest.fixture
def channel() -> str:
    return f"gimbal-test-{next(_channels)}"


@pytest.fixture
def listener(channel: str) -> Iterator[can.BusABC]:
    bus = can.Bus(interface="virtual", channel=channel)
    yield bus
    bus.shutdown()


def drain(bus: can.BusABC) -> list[can.Message]:
    frames = []
    while (frame := bus.recv(0)) is not None:
        frames.append(frame)
    return frames


def test_packet_frames_cut_into_eights() -> None:
    raw = bytes(range(26))
    frames = packet_frames(raw, 0x223)
    assert [len(f.data) for f in frames] == [8, 8, 8, 2]
    assert b"".join(bytes(f.data) for f in frames) == raw
    assert all(f.arbitration_id == 0x223 and not f.is_extended_id for f in frames)


def test_send_and_receive_between_two_ends(channel: str) -> None:
    host_bus = can.Bus(interface="virtual", channel=channel)
    device_bus = can.Bus(interface="virtual", channel=channel)
    try:
        host, device = CanTransport(host_bus), CanTransport(device_bus, tx_id=0x222, rx_id=0x223)
        command = message_packet(SpeedControl(10, 0, 0), 5)
        host.send(command)
        assert device.recv(1.0) == command
        reply = message_packet(AnglesReply(0, 1, 2, 3, 4), 5)
        device.send(encode_packet(reply))
        assert host.recv(1.0) == reply
        assert host.recv(0) is None
    finally:
        host_bus.shutdown()
        device_bus.shutdown()


def sent_packets(count: int, base_seq: int) -> list[Packet]:
    push = ParameterPush(7, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15)
    messages = [SpeedControl(1, 2, 3), push, AnglesReply(0, 1, 2, 3, 4)]
    return [message_packet(messages[i % 3], base_seq + i) for i in range(count)]


@pytest.mark.parametrize("shared_transport", [True, False])
def test_concurrent_senders_never_interleave(channel: str, listener: can.BusABC, shared_transport: bool) -> None:
    bus = YieldingBus(channel)
    try:
        transports = [CanTransport(bus)] * 2 if shared_transport else [CanTransport(bus), CanTransport(bus)]
        work = [sent_packets(150, 0), sent_packets(150, 1000)]
        threads = [threading.Thread(target=lambda t=t, w=w: [t.send(p) for p in w])
                   for t, w in zip(transports, work)]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
        frames = drain(listener)
    finally:
        bus.shutdown()
    # Each packet's frames must be consecutive: re-cut the frame sequence packet by packet.
    expected = {encode_packet(p) for w in work for p in w}
    index = 0
    while index < len(frames):
        raw = bytes(frames[index].data)
        count = (decode_packet_length(raw) + 7) // 8
        packet_bytes = b"".join(bytes(f.data) for f in frames[index:index + count])
        assert packet_bytes in expected, f"frames interleaved at frame {index}"
        expected.discard(packet_bytes)
        index += count
    assert not expected


def decode_packet_length(first_frame: bytes) -> int:
    return (first_frame[1] | first_frame[2] << 8) & 0x3FF


def test_foreign_ids_and_odd_frames_are_ignored(channel: str) -> None:
    bus = can.Bus(interface="virtual", channel=channel)
    sender = can.Bus(interface="virtual", channel=channel)
    try:
        transport = CanTransport(bus)
        reply = encode_packet(message_packet(AnglesReply(0, 1, 2, 3, 4), 9))
        noise = [
            can.Message(arbitration_id=0x530, data=b"\x55\xaa\x01\x02\x03\x04\x05\x06", is_extended_id=False),
            can.Message(arbitration_id=0x426, data=b"\xaa\x1a\x00\x03", is_extended_id=False),
            can.Message(arbitration_id=0x222, data=b"\xaa\x1a\x00\x03", is_extended_id=True),
            can.Message(arbitration_id=0x223, data=b"\xaa\x1a\x00\x03", is_extended_id=False),
            can.Message(arbitration_id=0x222, is_remote_frame=True, is_extended_id=False),
        ]
        for i, frame in enumerate(packet_frames(reply, 0x222)):
            sender.send(noise[i % len(noise)])
            sender.send(frame)
        assert transport.recv(1.0) == decode_packet(reply)
        assert transport.recv(0) is None
        assert transport.foreign_frames == 4
    finally:
        bus.shutdown()
        sender.shutdown()


def test_corrupted_frames_surface_as_drops(channel: str) -> None:
    bus = can.Bus(interface="virtual", channel=channel)
    sender = can.Bus(interface="virtual", channel=channel)
    try:
        transport = CanTransport(bus)
        good = encode_packet(message_packet(AnglesReply(0, 1, 2, 3, 4), 9))
        bad = bytearray(good)
        bad[17] ^= 0xFF
        for raw in (bytes(bad), good):
            for frame in packet_frames(raw, 0x222):
                sender.send(frame)
        first = transport.recv(1.0)
        assert isinstance(first, Dropped) and first.reason == "crc32"
        assert transport.recv(1.0) == decode_packet(good)
    finally:
        bus.shutdown()
        sender.shutdown()


def test_a_packet_after_a_lost_last_frame_is_kept(channel: str) -> None:
    # A's last frame holds only its final CRC byte, 0xAA; lost, B's SOF completes A. B must survive.
    a = next(raw for seq in range(0x10000) if (raw := encode_packet(
        Packet(cmd_type=0x20, seq=seq, data=bytes.fromhex("0e 04 00 91 37 b3 b3 1e 1e"))))[-1] == 0xAA)
    b = encode_packet(message_packet(AnglesReply(0, 1, 32, 48, 64), 7))
    bus = can.Bus(interface="virtual", channel=channel)
    try:
        transport = CanTransport(bus)
        for frame in packet_frames(a, 0x222)[:-1] + packet_frames(b, 0x222):
            transport.feed_frame(frame)
        assert [transport.recv(0), transport.recv(0), transport.recv(0)] == \
            [decode_packet(a), decode_packet(b), None]
    finally:
        bus.shutdown()


@pytest.fixture
def no_can_config(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> pytest.MonkeyPatch:
    """python-can with no configuration anywhere: no can.rc, no CAN_* variables, no ~/.canrc."""
    monkeypatch.setattr(can, "rc", {})
    monkeypatch.setenv("HOME", str(tmp_path))
    for name in ("CAN_INTERFACE", "CAN_CHANNEL", "CAN_BITRATE", "CAN_CONFIG"):
        monkeypatch.delenv(name, raising=False)
    return monkeypatch


@pytest.mark.parametrize("interface", ["gs_usb", "pcan", "slcan", "kvaser", "socketcan", "virtual"])
def test_the_bitrate_defaults_to_the_documents_1_mbit(no_can_config: pytest.MonkeyPatch,
                                                      interface: str) -> None:
    assert with_default_bitrate({"interface": interface}) == {"interface": interface,
                                                              "bitrate": 1_000_000}


@pytest.mark.parametrize("where", ["option", "can.rc", "CAN_BITRATE", "CAN_CONFIG timing"])
def test_a_given_or_configured_bitrate_is_left_alone(no_can_config: pytest.MonkeyPatch,
                                                     where: str) -> None:
    options: dict[str, object] = {"interface": "pcan"}
    if where == "option":
        options["bitrate"] = 500_000
    elif where == "can.rc":
        no_can_config.setattr(can, "rc", {"bitrate": 250_000})
    elif where == "CAN_BITRATE":
        no_can_config.setenv("CAN_BITRATE", "125000")
    else:
        no_can_config.setenv("CAN_CONFIG", json.dumps({"f_clock": 8_000_000, "brp": 1, "tseg1": 5,
                                                       "tseg2": 2, "sjw": 1, "nof_samples": 1}))
    assert with_default_bitrate(options) == options


def test_a_bus_built_by_the_client_gets_the_default_bitrate(no_can_config: pytest.MonkeyPatch) -> None:
    opened: list[dict[str, object]] = []

    def fake_bus(**kwargs: object) -> can.BusABC:
        opened.append(kwargs)
        raise can.CanInitializationError("no adapter")

    no_can_config.setattr(can, "Bus", fake_bus)
    with pytest.raises(BusError, match="no adapter"):
        GimbalClient(interface="gs_usb", channel="0")
    assert opened == [{"interface": "gs_usb", "channel": "0", "bitrate": 1_000_000}]


# ``CanTransport.recv(timeout)`` keeps its deadline on a busy bus: DJI's accessory traffic on
# other ids (0x530/0x531/0x426, thousands of frames a second, FIELD_NOTES.md "Transport") never
# yields a packet, and must not keep the caller waiting past its timeout.
TIMEOUT_S = 0.05
FLOOD_S = 3.0  # the fake bus falls silent after this long, so a transport that ignores its deadline returns late


class FloodedBus(can.BusABC):
    """A bus with an endless stream of accessory frames on 0x530 (for ``FLOOD_S`` seconds)."""

    def __init__(self) -> None:
        super().__init__(channel="flooded")
        self._until = time.monotonic() + FLOOD_S

    def send(self, msg: can.Message, timeout: float | None = None) -> None:
        """Nothing listens."""

    def _recv_internal(self, timeout: float | None) -> tuple[can.Message | None, bool]:
        if time.monotonic() >= self._until:
            return None, False
        time.sleep(0.0005)
        return can.Message(arbitration_id=0x530, is_extended_id=False, data=b"\x55\x0d\x04\x33"), False


def test_recv_returns_none_at_its_deadline_while_foreign_frames_keep_coming() -> None:
    bus = FloodedBus()
    try:
        transport = CanTransport(bus)
        start = time.monotonic()
        assert transport.recv(TIMEOUT_S) is None
        assert time.monotonic() - start < TIMEOUT_S + 1.0  # a loaded machine may stall; ignoring the deadline costs 3 s
        assert transport.foreign_frames > 0
    finally:
        bus.shutdown()
