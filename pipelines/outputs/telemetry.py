"""Telemetry as JSON Lines: one object per frame, each line flushed as soon as it is written."""
from __future__ import annotations

import json
import os
from collections.abc import Mapping
from pathlib import Path
from types import TracebackType
from typing import Any

from pipelines.outputs._files import to_plain
from tracker.runtime.estimate import TargetEstimate

#: What ``json.dumps(..., separators=(",", ":"), allow_nan=False)`` builds on every call.
_ENCODER = json.JSONEncoder(separators=(",", ":"), allow_nan=False)


def estimate_fields(estimate: TargetEstimate) -> dict[str, Any]:
    """The tracker part of a telemetry record (keys as documented in docs/outputs.md); the frame's
    ``frame`` and ``t`` come from the source's ``Frame``, not from here."""
    return {
        "box": list(estimate.box),
        "velocity": list(estimate.velocity),
        "confidence": estimate.confidence,
        "state": estimate.state.value,
    }


class TelemetryWriter:
    """Appends one JSON object per ``write`` to a .jsonl file and flushes it, so a crash loses nothing."""

    def __init__(self, path: str | os.PathLike[str], append: bool = False) -> None:
        self.path = Path(path)
        self._file = open(self.path, "a" if append else "w", encoding="utf-8")
        self.records = 0

    def write(self, record: Mapping[str, Any]) -> None:
        """Write ``record`` (numpy values, enums and tuples allowed; NaN is written as null)."""
        line = _ENCODER.encode(to_plain(record))
        try:
            self._file.write(line + "\n")
            self._file.flush()
        except OSError as exc:
            raise OSError(f"cannot write the telemetry {self.path}: {exc.strerror or exc}") from exc
        self.records += 1

    def close(self) -> None:
        self._file.close()

    def __enter__(self) -> TelemetryWriter:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close()


def read_telemetry(path: str | os.PathLike[str]) -> list[dict[str, Any]]:
    """All records of a telemetry file; a torn last line (the writer was killed mid-line) is ignored."""
    lines = Path(path).read_text(encoding="utf-8").splitlines()
    records = []
    for number, line in enumerate(lines, 1):
        try:
            records.append(json.loads(line))
        except json.JSONDecodeError:
            if number == len(lines):
                break
            raise ValueError(f"{path}:{number}: not a JSON object") from None
    return records
