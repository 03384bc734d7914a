"""The message base class: a declarative payload layout, range checks and a registry."""
from __future__ import annotations

import dataclasses
import struct
from collections.abc import Mapping
from enum import Enum
from numbers import Integral
from typing import Any, ClassVar, Self, TypeVar

from gimbal.errors import PayloadError, RangeError
from gimbal.values import shown

GIMBAL_CMD_SET = 0x0E
CAMERA_CMD_SET = 0x0D
CMD_SETS = (GIMBAL_CMD_SET, CAMERA_CMD_SET)

_TYPE_RANGES = {"b": (-0x80, 0x7F), "B": (0, 0xFF), "h": (-0x8000, 0x7FFF), "H": (0, 0xFFFF),
                "i": (-0x80000000, 0x7FFFFFFF), "I": (0, 0xFFFFFFFF)}


class Kind(str, Enum):
    COMMAND = "command"  # host -> device, may want a reply
    REPLY = "reply"  # device -> host, answers a command
    PUSH = "push"  # unsolicited, never answered (either direction)


class Sender(str, Enum):
    HOST = "host"
    DEVICE = "device"


@dataclasses.dataclass
class Message:
    """One command, reply or push of the document.

    Subclasses are dataclasses whose fields follow the document, in wire order, with raw wire
    values (0.1° units). Fixed layouts set ``FORMAT`` (struct codes, little-endian, one per field);
    variable ones (TLVs) override ``encode_payload``/``decode_payload``.
    """

    CMD_SET: ClassVar[int]
    CMD_ID: ClassVar[int]
    KIND: ClassVar[Kind]
    SENDER: ClassVar[Sender]
    NAME: ClassVar[str]
    FORMAT: ClassVar[str] = ""
    RANGES: ClassVar[Mapping[str, tuple[int, int]]] = {}
    UNITS: ClassVar[Mapping[str, tuple[float, str]]] = {}  # field -> (one raw step, unit), for errors
    CHOICES: ClassVar[Mapping[str, frozenset[int]]] = {}
    REPLY: ClassVar[type[Message] | None] = None  # a command's reply; None: the document has none
    PARTIAL: ClassVar[bool] = False  # a shorter payload decodes with the missing fields as None

    def encode_payload(self) -> bytes:
        """The payload bytes (after CmdSet/CmdID); validates first."""
        layout = _layout(type(self))
        values = [getattr(self, name) for name in layout.names]
        self._check(layout, values)
        if self.PARTIAL and None in values:  # e.g. a NACK reply carrying its return code alone
            present = values.index(None)
            return struct.pack("<" + self.FORMAT[:present], *values[:present])
        return layout.struct.pack(*values)

    @classmethod
    def decode_payload(cls, payload: bytes) -> Self:
        """Parse a payload; extra trailing bytes are ignored, missing ones raise (or are None if
        ``PARTIAL``)."""
        layout = _layout(cls)
        if len(payload) >= layout.struct.size:
            return cls(*layout.struct.unpack_from(payload))
        values: list[int | None] = []
        offset = 0
        for code in cls.FORMAT:
            size = _CODE_SIZES[code]
            if offset + size > len(payload):
                if not (cls.PARTIAL and values):
                    raise PayloadError(f"{cls.NAME}: payload of {len(payload)} bytes is shorter than "
                                       f"the {layout.struct.size} the document defines")
                values.append(None)
                continue
            values.append(struct.unpack_from("<" + code, payload, offset)[0])
            offset += size
        return cls(*values)

    @classmethod
    def matches(cls, payload: bytes) -> bool:
        """Whether ``payload`` is this message rather than a sibling on the same CmdSet/CmdID."""
        return True

    def reply_is_mine(self, reply_payload: bytes) -> bool:
        """Whether a reply payload (return code first) answers this very command rather than
        another of its class (a version reply names the device asked about); True by default."""
        return True

    def validate(self) -> None:
        """Raise ``RangeError`` for any field outside the document's range."""
        layout = _layout(type(self))
        self._check(layout, [getattr(self, name) for name in layout.names])

    def _check(self, layout: _Layout, values: list[Any]) -> None:
        missing = False
        for (name, low, high, allowed), value in zip(layout.checks, values):
            if value is None and self.PARTIAL:
                missing = True
                continue
            if missing:
                raise RangeError(f"{self.NAME}.{name} is set but an earlier field is missing: "
                                 "only trailing fields may be left out")
            if value.__class__ is not int and (not isinstance(value, Integral) or isinstance(value, bool)):
                raise RangeError(f"{self.NAME}.{name} must be an integer, not {shown(value)}")
            if not low <= value <= high:
                raise RangeError(f"{self.NAME}.{name}={shown(value)} is outside {low}..{high}"
                                 + self._in_units(name, value, low, high))
            if allowed is not None and value not in allowed:
                listed = ", ".join(f"0x{v:02X}" for v in sorted(allowed))
                raise RangeError(f"{self.NAME}.{name}=0x{value:02X} is not one of {listed}")

    def _in_units(self, name: str, value: int, low: int, high: int) -> str:
        """`` (300°: -180..180°)`` for a field with a unit, else nothing."""
        if name not in self.UNITS:
            return ""
        step, unit = self.UNITS[name]
        return f" ({shown(value * step)}{unit}: allowed {low * step:g}..{high * step:g}{unit})"

    def fields(self) -> dict[str, Any]:
        """The fields as JSON-friendly values (bytes as hex)."""
        return {f.name: _jsonable(getattr(self, f.name)) for f in dataclasses.fields(self)}


_CODE_SIZES = {code: struct.calcsize("<" + code) for code in _TYPE_RANGES}


@dataclasses.dataclass(frozen=True, slots=True)
class _Layout:
    """What encoding and decoding a fixed-layout class needs, computed once per class."""

    names: tuple[str, ...]
    struct: struct.Struct
    checks: tuple[tuple[str, int, int, frozenset[int] | None], ...]


def _layout(cls: type[Message]) -> _Layout:
    layout = cls.__dict__.get("_LAYOUT")
    if layout is None:
        names = tuple(f.name for f in dataclasses.fields(cls))[:len(cls.FORMAT)]
        checks = tuple((name, *cls.RANGES.get(name, _TYPE_RANGES[code]), cls.CHOICES.get(name))
                       for name, code in zip(names, cls.FORMAT))
        layout = _Layout(names, struct.Struct("<" + cls.FORMAT), checks)
        cls._LAYOUT = layout  # type: ignore[attr-defined]  # cached on the class itself
    return layout


def _jsonable(value: Any) -> Any:
    if isinstance(value, Integral) and type(value) is not bool:  # numpy's integers too
        return int(value)
    if isinstance(value, bytes):
        return value.hex()
    if isinstance(value, tuple | list):
        return [_jsonable(v) for v in value]
    if dataclasses.is_dataclass(value):
        return {f.name: _jsonable(getattr(value, f.name)) for f in dataclasses.fields(value)}
    return value


# Registries keyed by (CmdSet, CmdID); several classes may share a key (sub-commands).
HOST_MESSAGES: dict[tuple[int, int], list[type[Message]]] = {}
DEVICE_PUSHES: dict[tuple[int, int], list[type[Message]]] = {}
REPLIES: dict[tuple[int, int], list[type[Message]]] = {}


M = TypeVar("M", bound=type[Message])


def register(cls: M) -> M:
    """Class decorator: make ``cls`` findable by the decoder."""
    key = (cls.CMD_SET, cls.CMD_ID)
    if cls.KIND is Kind.REPLY:
        table = REPLIES
    elif cls.SENDER is Sender.DEVICE:
        table = DEVICE_PUSHES
    else:
        table = HOST_MESSAGES
    table.setdefault(key, []).append(cls)
    return cls


def all_message_classes() -> list[type[Message]]:
    """Every registered class, commands first, in CmdSet/CmdID order."""
    found = [c for table in (HOST_MESSAGES, DEVICE_PUSHES, REPLIES) for cs in table.values() for c in cs]
    return sorted(found, key=lambda c: (-c.CMD_SET, c.CMD_ID, c.KIND is Kind.REPLY))


@dataclasses.dataclass(frozen=True)
class Tlv:
    """One ID + LENGTH + VALUE entry."""

    id: int
    value: bytes

    def encode(self) -> bytes:
        if not 0 <= self.id <= 0xFF or len(self.value) > 0xFF:
            raise RangeError(f"TLV id 0x{self.id:X} with {len(self.value)} bytes does not fit a TLV")
        return bytes((self.id, len(self.value))) + self.value


def encode_tlvs(tlvs: tuple[Tlv, ...]) -> bytes:
    return b"".join(t.encode() for t in tlvs)


def decode_tlvs(data: bytes, name: str) -> tuple[Tlv, ...]:
    """Split a TLV buffer; a truncated entry raises ``PayloadError``."""
    tlvs = []
    offset = 0
    while offset < len(data):
        if offset + 2 > len(data) or offset + 2 + data[offset + 1] > len(data):
            raise PayloadError(f"{name}: TLV at byte {offset} runs past the end of the payload")
        length = data[offset + 1]
        tlvs.append(Tlv(data[offset], bytes(data[offset + 2:offset + 2 + length])))
        offset += 2 + length
    return tuple(tlvs)
