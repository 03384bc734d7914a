"""DJI R SDK codec throughput on one core, against what a saturated 1 Mbit/s CAN bus can carry.

Run: .venv/bin/python benchmarks/bench_codec.py [--seconds 1.0]
"""
from __future__ import annotations

import argparse
import math
import time
from collections.abc import Callable

from gimbal.framer import PacketFramer
from gimbal.messages import decode_message, message_packet
from gimbal.messages.motion import AnglesReply, GetAngles, SpeedControl, SpeedControlReply
from gimbal.messages.telemetry import ParameterPush
from gimbal.packet import decode_packet, encode_packet
from machine import describe_machine

BITRATE = 1_000_000
TARGET_RATIO = 20.0


def can_frame_bits(data_bytes: int) -> tuple[int, int]:
    """Bits of one classic standard-id data frame: (without stuffing, worst-case stuff bits).

    SOF 1 + id 11 + RTR 1 + IDE 1 + r0 1 + DLC 4 + data 8n + CRC 15 = 34 + 8n stuffable bits,
    then CRC delimiter 1 + ACK 2 + EOF 7 + intermission 3 = 13 fixed bits. At most one stuff bit
    per 4 stuffable bits after the first.
    """
    stuffable = 34 + 8 * data_bytes
    return stuffable + 13, (stuffable - 1) // 4


def packet_bits(packet_len: int) -> tuple[int, int]:
    """(bits without stuffing, worst-case stuff bits) of a packet cut into 8-byte frames."""
    sizes = [8] * (packet_len // 8) + ([packet_len % 8] if packet_len % 8 else [])
    bits = [can_frame_bits(n) for n in sizes]
    return sum(b for b, _ in bits), sum(s for _, s in bits)


def mix() -> list[tuple[object, type | None]]:
    """A tracking session's traffic: speed commands and their replies, attitude polls and
    replies, 40-byte parameter pushes."""
    return [
        (SpeedControl(yaw_speed=123, roll_speed=0, pitch_speed=-45, ctrl_byte=0x88), None),
        (SpeedControlReply(return_code=0), SpeedControl),
        (GetAngles(ctrl_byte=1), None),
        (AnglesReply(return_code=0, data_type=1, yaw=-312, roll=4, pitch=87), GetAngles),
        (ParameterPush(7, 1, 2, 3, 4, 5, 6, 145, 55, 179, 179, 30, 30, 50, 50, 50), None),
        (ParameterPush(7, -11, 22, -33, 44, -55, 66, 140, 50, 170, 170, 25, 25, 40, 60, 80), None),
    ]


def round_trip(items: list[tuple[object, type | None]]) -> Callable[[int], None]:
    """One encode + decode of every item per iteration (message -> bytes -> message)."""
    def run(seq: int) -> None:
        for message, request in items:
            raw = encode_packet(message_packet(message, seq))
            decode_message(decode_packet(raw), request)
    return run


def stream_decode(items: list[tuple[object, type | None]]) -> Callable[[int], None]:
    """Decode only, the way the transport does: 8-byte frames through the framer."""
    stream = b"".join(encode_packet(message_packet(m, 1)) for m, _ in items)
    frames = [stream[i:i + 8] for i in range(0, len(stream), 8)]
    framer = PacketFramer()

    def run(seq: int) -> None:
        for frame in frames:
            for packet in framer.feed(frame):
                decode_message(packet, None if not packet.is_reply else GetAngles)
    return run


def rate(run: Callable[[int], None], per_call: int, seconds: float) -> float:
    """Best of three runs, in packets per second."""
    best = 0.0
    for _ in range(3):
        calls, start = 0, time.perf_counter()
        while (elapsed := time.perf_counter() - start) < seconds / 3:
            for seq in range(100):
                run(seq)
            calls += 100
        best = max(best, calls * per_call / elapsed)
    return best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=1.5, help="time per measurement")
    args = parser.parse_args()

    attitude = [m for m in mix() if isinstance(m[0], AnglesReply)]
    attitude_len = len(encode_packet(message_packet(attitude[0][0], 1)))
    plain, stuff = packet_bits(attitude_len)
    estimate = plain + stuff // 2
    frames = math.ceil(attitude_len / 8)
    print(describe_machine())
    print(f"bus model: a {attitude_len}-byte packet = {frames} classic CAN frames = {plain} bits unstuffed, "
          f"{plain + stuff} with worst-case stuffing; assumed {estimate} (half the worst-case stuffing)")
    bus_rate, bus_best = BITRATE / estimate, BITRATE / plain
    print(f"saturated 1 Mbit/s bus: {bus_rate:,.0f} packets/s assumed ({bus_best:,.0f} with no stuffing at all)")

    results = {
        "mix, encode+decode": rate(round_trip(mix()), len(mix()), args.seconds),
        f"{attitude_len}-byte attitude reply, encode+decode": rate(round_trip(attitude), 1, args.seconds),
        "mix, decode from 8-byte frames (framer)": rate(stream_decode(mix()), len(mix()), args.seconds),
    }
    width = max(map(len, results))
    for name, value in results.items():
        print(f"{name:<{width}}  {value:>10,.0f} packets/s  {value / bus_rate:6.1f}x bus "
              f"({value / bus_best:.1f}x unstuffed bound)")
    worst = min(results.values()) / bus_rate
    print(f"slowest path is {worst:.1f}x a saturated bus (target {TARGET_RATIO:.0f}x): "
          + ("OK" if worst >= TARGET_RATIO else "BELOW TARGET"))


if __name__ == "__main__":
    main()
