"""Fault injection: lost, corrupted and delayed frames, NACKs, silence, legacy replies, foreign
traffic. Each kind of event draws from its own RNG seeded from ``seed``, so the nth reply's fate
does not depend on how many pushes or foreign frames the other thread drew before it: the same
seed and the same commands give the same faults."""
from __future__ import annotations

import random
from collections import Counter
from dataclasses import dataclass

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
        for name in ("drop", "corrupt", "nack", "legacy"):
            value = getattr(self, name)
            if not 0.0 <= value <= 1.0:
                raise ValueError(f"Faults.{name} is a fraction in 0..1, not {value}")
        if self.direction not in DIRECTIONS:
            raise ValueError(f"Faults.direction must be one of {', '.join(DIRECTIONS)}, not {self.direction!r}")
        if self.delay_s < 0:
            raise ValueError("Faults.delay_s cannot be negative")
        if not 0 <= self.foreign_rate <= MAX_FOREIGN_RATE_HZ:
            raise ValueError(f"Faults.foreign_rate is 0 to {MAX_FOREIGN_RATE_HZ} frames/s, not {self.foreign_rate}")
        if not 0 <= self.nack_code <= 0xFF:
            raise ValueError(f"Faults.nack_code {self.nack_code} does not fit a byte")
        if self.silent is not None and not 0 <= self.silent[0] <= self.silent[1]:
            raise ValueError(f"Faults.silent {self.silent} must be (start, end) with 0 <= start <= end")


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
