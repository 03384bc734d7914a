"""What counts as a number, an integer or a flag where a value is checked (the client's arguments,
the simulator's settings): numpy's count as Python's, bools are not numbers, and strings such as
"no", which Python takes as true, are not flags; and how a bad value is shown in a message."""
from __future__ import annotations

import math
from collections.abc import Callable
from decimal import Decimal
from numbers import Integral, Real

#: A test of one value: False for anything out of range, NaN and infinities included.
Test = Callable[[object], bool]


def number(low: float = -math.inf, high: float = math.inf, *, above: bool = False) -> Test:
    """Finite real numbers from ``low`` (or above it, with ``above``) to ``high``; no bools."""
    def test(value: object) -> bool:
        if isinstance(value, bool) or not isinstance(value, Real) or not math.isfinite(value):
            return False
        return (low < value if above else low <= value) and value <= high
    return test


def integer(low: int, high: float = math.inf) -> Test:
    """Integers (numpy's too) from ``low`` to ``high``; no bools."""
    return lambda value: isinstance(value, Integral) and not isinstance(value, bool) and low <= value <= high


def is_flag(value: object) -> bool:
    """Whether ``value`` is True or False (numpy's bools too); 0, 1 and strings such as "no", which
    Python takes as true, are not."""
    return isinstance(value, bool) or (type(value).__module__ == "numpy" and type(value).__name__ in ("bool", "bool_"))


#: Integers with more digits than this are shown in scientific notation in messages.
MAX_SHOWN_DIGITS = 15


def shown(value: object) -> str:
    """``value`` as a message shows it: a huge number compactly (``1e+308``, ``-1e+40``), not with
    its hundreds of digits; anything else as its repr (strings quoted)."""
    if isinstance(value, bool):
        return repr(value)
    if isinstance(value, Integral):
        number = int(value)
        if abs(number) < 10 ** MAX_SHOWN_DIGITS:
            return str(number)
        mantissa, exponent = f"{Decimal(number):.5e}".split("e")
        return f"{mantissa.rstrip('0').rstrip('.')}e{exponent}"
    if isinstance(value, Real):  # 1e+308, 31, 0.1; a float :g would round is shown whole
        number = float(value)
        compact = f"{number:g}"
        return compact if not math.isfinite(number) or float(compact) == number else repr(number)
    return repr(value)
