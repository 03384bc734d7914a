"""Fault injection: lost, corrupted and delayed frames, NACKs, silence, legacy replies, foreign
traffic. Each kind of event draws from its own RNG seeded from ``seed``, so the nth reply's fate
does not depend on how many pushes or foreign frames the other thread drew before it: the same
seed and the same commands give the same faults."""
from __future__ import annotations

import math
import random
from collections import Counter
from dataclasses import dataclass

from gimbal.sim.checks import check
from gimbal.values import integer, number

DIRECTIONS = ("both", "rx", "tx")
FOREIGN_IDS = (0x530, 0x531, 0x426)  # DJI's internal accessory traffic seen on live buses
MAX_FOREIGN_RATE_HZ = 20_000  # more frames than a 1 Mbit/s classic CAN bus carries (~9,000-18,000/s)
#: The RNG streams: frames received, reply frames, push frames, NACKs, legacy replies, foreign traffic.
STREAMS = ("rx", "replies", "pushes", "nack", "legacy", "foreign")


@dataclass(frozen=True)
class Faults:
    """Which faults to inject; the defaults inject none."""

    drop: float = 0.0  # fraction of CAN frames lost
    corrupt: float = 0.0  # fraction of CAN frames with one byte altered
    direction: str = "both"  # where drop/corrupt apply: "rx" (host -> sim), "tx" or "both"
    delay_s: float = 0.0  # every reply leaves this much later
    nack: float = 0.0  # fraction of commands refused (not executed) with ``nack_code``
    nack_code: int = 0x02
    silent: tuple[float, float] | None = None  # (start, end) s after start(): deaf and mute
    legacy: float = 0.0  # fraction of replies in the legacy layout whatever the firmware mode
    foreign_rate: float = 0.0  # foreign frames per second added to the bus
    seed: int = 0

    def __post_init__(self) -> None:
        check(self, RULES)


def _window(value: object) -> bool:
    """None, or (start, end) seconds with 0 <= start <= end; start finite, end may be inf (for ever)."""
    return value is None or (isinstance(value, tuple) and len(value) == 2 and number(0)(value[0])
                             and (value[1] == math.inf or number(value[0])(value[1])))


_FRACTION = ("a fraction from 0 to 1", number(0, 1))
#: field: (what it takes, test); NaN fails every test. ``delay_s``'s words leave the unit out (the
#: CLI takes milliseconds).
RULES = {
    "drop": _FRACTION, "corrupt": _FRACTION,
    "direction": (f"one of {', '.join(DIRECTIONS)}", lambda v: v in DIRECTIONS),
    "delay_s": ("a finite delay, 0 or more", number(0)),
    "nack": _FRACTION,
    "nack_code": ("a return code, 1 to 0xFF (0 means executed)", integer(1, 0xFF)),
    "silent": ("a window START:END in seconds, 0 <= START <= END (END may be inf)", _window),
    "legacy": _FRACTION,
    "foreign_rate": (f"a rate from 0 to {MAX_FOREIGN_RATE_HZ} Hz (a 1 Mbit/s bus carries less)",
                     number(0, MAX_FOREIGN_RATE_HZ)),
}


class FaultInjector:
    """Applies ``Faults`` frame by frame and counts what it did (``counts``)."""

    def __init__(self, faults: Faults) -> None:
        self.faults = faults
        self.counts: Counter[str] = Counter()
        self._rngs = {name: random.Random(f"{faults.seed}/{name}") for name in STREAMS}
        self._foreign_due = 0.0

    def silent(self, elapsed: float) -> bool:
        window = self.faults.silent
        return window is not None and window[0] <= elapsed < window[1]

    def frame(self, data: bytes, stream: str) -> bytes | None:
        """A frame's data after loss and corruption (None: lost); ``stream`` is "rx" for a frame
        received, "replies" or "pushes" for one sent (direction tx)."""
        direction = "rx" if stream == "rx" else "tx"
        if self.faults.direction not in ("both", direction):
            return data
        rng = self._rngs[stream]
        if self.faults.drop and rng.random() < self.faults.drop:
            self.counts[f"dropped_{direction}"] += 1
            return None
        if self.faults.corrupt and data and rng.random() < self.faults.corrupt:
            self.counts[f"corrupted_{direction}"] += 1
            index = rng.randrange(len(data))
            altered = bytearray(data)
            altered[index] ^= rng.randrange(1, 256)
            return bytes(altered)
        return data

    def nack(self) -> int | None:
        """The return code to refuse this command with, or None to execute it."""
        if self.faults.nack and self._rngs["nack"].random() < self.faults.nack:
            self.counts["nacks"] += 1
            return self.faults.nack_code
        return None

    def legacy_reply(self) -> bool:
        if self.faults.legacy and self._rngs["legacy"].random() < self.faults.legacy:
            self.counts["legacy_replies"] += 1
            return True
        return False

    def foreign_frames(self, dt: float) -> list[tuple[int, bytes]]:
        """The foreign (id, data) frames due over ``dt`` seconds: 0x55-led packets cut in 8-byte
        pieces and random bytes, on DJI's accessory ids."""
        self._foreign_due += self.faults.foreign_rate * dt
        count, self._foreign_due = int(self._foreign_due), self._foreign_due % 1.0
        rng = self._rngs["foreign"]
        frames = []
        for _ in range(count):
            data = bytearray(rng.randbytes(rng.randint(1, 8)))
            if rng.random() < 0.5:
                data[0] = 0x55
            frames.append((rng.choice(FOREIGN_IDS), bytes(data)))
        self.counts["foreign_sent"] += len(frames)
        return frames
