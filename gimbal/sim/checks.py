"""The range checks of ``SimConfig`` and ``Faults``: every failure is a ``FieldError`` that names
the field, so that a front end (``gimbaltrack sim``) can name its own option instead."""
from __future__ import annotations

import math
from collections.abc import Callable
from numbers import Integral, Real

from gimbal.messages.base import is_flag


class FieldError(ValueError):
    """``owner.field`` (e.g. ``Faults.delay_s``) takes ``takes`` (words without the field's unit
    where a front end may use another), not ``value``."""

    def __init__(self, owner: str, field: str, takes: str, value: object) -> None:
        super().__init__(f"{owner}.{field} takes {takes}, not {value!r}")
        self.owner, self.field, self.takes, self.value = owner, field, takes, value

    @property
    def name(self) -> str:
        """``owner.field``."""
        return f"{self.owner}.{self.field}"


#: A test of one value: False for anything out of range, NaN and infinities included.
Test = Callable[[object], bool]


def number(low: float = -math.inf, high: float = math.inf, *, above: bool = False) -> Test:
    """Finite real numbers from ``low`` (or above it, with ``above``) to ``high``; no bools."""
    def test(value: object) -> bool:
        if isinstance(value, bool) or not isinstance(value, Real) or not math.isfinite(value):
            return False
        return (low < value if above else low <= value) and value <= high
    return test


def integer(low: int, high: int) -> Test:
    """Integers (numpy's too) from ``low`` to ``high``; no bools."""
    return lambda value: isinstance(value, Integral) and not isinstance(value, bool) and low <= value <= high


def check(instance: object, rules: dict[str, tuple[str, Test]]) -> None:
    """Raise ``FieldError`` for the first field of ``instance`` that fails its rule (field: (takes, test));
    bools and numbers of other types (numpy's) that pass are stored as Python's, which the message
    codec and the JSON status lines expect."""
    for field, (takes, test) in rules.items():
        value = getattr(instance, field)
        if not test(value):
            raise FieldError(type(instance).__name__, field, takes, value)
        if type(value) not in (int, float, bool) and (is_flag(value) or isinstance(value, Real)):
            object.__setattr__(instance, field, _plain(value))


def _plain(value: object) -> bool | int | float:
    """A numpy bool or number as Python's."""
    return bool(value) if is_flag(value) else int(value) if isinstance(value, Integral) else float(value)
