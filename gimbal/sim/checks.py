"""The range checks of ``SimConfig`` and ``Faults``: every failure is a ``FieldError`` that names
the field, so that a front end (``gimbaltrack sim``) can name its own option instead."""
from __future__ import annotations

from numbers import Integral, Real

from gimbal.values import Test, is_flag, shown


class FieldError(ValueError):
    """``owner.field`` (e.g. ``Faults.delay_s``) takes ``takes`` (words without the field's unit
    where a front end may use another), not ``value``."""

    def __init__(self, owner: str, field: str, takes: str, value: object) -> None:
        super().__init__(f"{owner}.{field} takes {takes}, not {shown(value)}")
        self.owner, self.field, self.takes, self.value = owner, field, takes, value

    @property
    def name(self) -> str:
        """``owner.field``."""
        return f"{self.owner}.{self.field}"


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
