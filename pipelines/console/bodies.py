"""The control requests' JSON bodies, checked before anything is changed.

Each parser returns the action's argument or raises ``RequestError`` with the HTTP status and a
one-line reason: 400 for a body that is not what the endpoint takes (bad JSON, unknown or missing
fields, wrong types), 422 for values out of range.
"""
from __future__ import annotations

import json
import math
from typing import Any

from pipelines.console.operator import SETTING_RANGES

MAX_BODY_BYTES = 4096  # the largest body any endpoint takes is a few dozen bytes


class RequestError(Exception):
    def __init__(self, status: int, reason: str) -> None:
        super().__init__(reason)
        self.status = status
        self.reason = reason


def parse_object(raw: bytes, allowed: tuple[str, ...]) -> dict[str, Any]:
    """The body as a JSON object with no keys outside ``allowed``; an empty body is ``{}``."""
    if not raw.strip():
        return {}
    try:
        body = json.loads(raw, parse_constant=_refuse_constant)
    except (UnicodeDecodeError, json.JSONDecodeError, ValueError) as exc:
        raise RequestError(400, f"the body is not valid JSON ({exc})") from None
    if not isinstance(body, dict):
        raise RequestError(400, f"the body must be a JSON object, not {type(body).__name__}")
    unknown = sorted(set(body) - set(allowed))
    if unknown:
        takes = ", ".join(allowed) if allowed else "no fields"
        raise RequestError(400, f"unknown field {unknown[0]!r} (this request takes {takes})")
    return body


def _refuse_constant(name: str) -> None:
    raise ValueError(f"{name} is not a number")


def _number(value: Any, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise RequestError(400, f"{name} must be a number, not {json.dumps(value)}")
    if not math.isfinite(value):
        raise RequestError(422, f"{name} must be finite")
    return float(value)


def parse_select(raw: bytes, frame_size: tuple[int, int] | None) -> tuple[float, float, float, float]:
    """``{"box": [x, y, w, h]}`` in source pixels: w and h above 2, at least half inside the frame."""
    body = parse_object(raw, ("box",))
    box = body.get("box")
    if not isinstance(box, list) or len(box) != 4:
        raise RequestError(400, 'select takes {"box": [x, y, w, h]} (four numbers, source pixels)')
    x, y, w, h = (_number(v, f"box[{i}]") for i, v in enumerate(box))
    if w < 2 or h < 2:
        raise RequestError(422, f"the box must be at least 2 x 2 pixels, not {w:g} x {h:g}")
    if frame_size is None:
        raise RequestError(409, "no frame has been processed yet: nothing to select in")
    width, height = frame_size
    x0, y0, x1, y1 = max(x, 0.0), max(y, 0.0), min(x + w, width), min(y + h, height)
    if x1 <= x0 or y1 <= y0 or (x1 - x0) * (y1 - y0) < 0.5 * w * h:
        raise RequestError(422, f"the box {x:g},{y:g},{w:g},{h:g} lies mostly outside the "
                                f"{width}x{height} frame")
    return x, y, w, h


def parse_record(raw: bytes) -> bool:
    """``{"on": true|false}``."""
    body = parse_object(raw, ("on",))
    on = body.get("on")
    if not isinstance(on, bool):
        raise RequestError(400, 'record takes {"on": true} or {"on": false}')
    return on


def parse_settings(raw: bytes) -> dict[str, float]:
    """Some of ``SETTING_RANGES``' keys, each a number within its range; at least one."""
    body = parse_object(raw, tuple(SETTING_RANGES))
    if not body:
        raise RequestError(400, f"settings takes one or more of {', '.join(SETTING_RANGES)}")
    changes = {}
    for name, value in body.items():
        number = _number(value, name)
        low, high = SETTING_RANGES[name]
        if not low <= number <= high:
            raise RequestError(422, f"{name} must be {low:g} to {high:g}, not {number:g}")
        changes[name] = number
    return changes


def parse_empty(raw: bytes) -> None:
    """Pause, resume, recenter and stop take no fields (an empty body or ``{}``)."""
    parse_object(raw, ())

