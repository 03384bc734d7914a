"""``--sim-faults``: the faults of ``gimbaltrack sim`` for the built-in simulated gimbal (``-i sim``),
as one option, so that a run against a flaky link is one command (and a fast test)."""
from __future__ import annotations

import argparse
from collections.abc import Callable
from typing import Any

from gimbal.sim import Faults
from gimbal.sim.checks import FieldError

#: key in the spec: (Faults field, parse); the keys are ``gimbaltrack sim``'s option names.
KEYS: dict[str, tuple[str, Callable[[str], Any]]] = {
    "drop": ("drop", float),
    "corrupt": ("corrupt", float),
    "fault-direction": ("direction", str),
    "delay-ms": ("delay_s", lambda text: float(text) / 1000.0),
    "nack": ("nack", float),
    "silent": ("silent", lambda text: tuple(float(part) for part in text.split(":", 1)) if ":" in text
               else float("nan")),
    "seed": ("seed", int),
}
USAGE = ("takes KEY=VALUE[,KEY=VALUE...] with keys " + ", ".join(KEYS)
         + " (as gimbaltrack sim's options), e.g. drop=0.2,silent=6:6.3")


def parse_sim_faults(spec: str) -> Faults:
    """``drop=0.2,silent=6:6.3`` as ``Faults``; ``argparse.ArgumentTypeError`` (one line, exit 2) otherwise."""
    fields: dict[str, Any] = {}
    for item in spec.split(","):
        key, sep, text = item.strip().partition("=")
        if not sep or key not in KEYS:
            raise argparse.ArgumentTypeError(f"{USAGE}, not {item.strip()!r}")
        field, parse = KEYS[key]
        try:
            fields[field] = parse(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{key} takes a number, not {text!r}") from None
    try:
        return Faults(**fields)
    except FieldError as exc:
        key = next(k for k, (field, _) in KEYS.items() if field == exc.field)
        raise argparse.ArgumentTypeError(f"{key} takes {exc.takes}") from None
