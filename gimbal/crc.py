"""The two CRCs of the DJI R SDK (document section 3.2), as pure functions.

CRC16: width 16, poly 0x8005, init 0xC55C, reflected in/out, xorout 0.
CRC32: width 32, poly 0x04C11DB7, init 0xC55C0000, reflected in/out, xorout 0.
"""
from __future__ import annotations

import zlib

_CRC16_INIT_REFLECTED = 0x3AA3  # 0xC55C with its 16 bits reversed
_CRC32_INIT_REFLECTED = 0x00003AA3  # 0xC55C0000 with its 32 bits reversed


def _crc16_table() -> tuple[int, ...]:
    table = []
    for byte in range(256):
        crc = byte
        for _ in range(8):
            crc = (crc >> 1) ^ 0xA001 if crc & 1 else crc >> 1  # 0xA001 = 0x8005 reflected
        table.append(crc)
    return tuple(table)


_CRC16_TABLE = _crc16_table()


def crc16(data: bytes) -> int:
    """CRC16 of ``data`` as the document defines it (the header check)."""
    crc = _CRC16_INIT_REFLECTED
    table = _CRC16_TABLE
    for byte in data:
        crc = (crc >> 8) ^ table[(crc ^ byte) & 0xFF]
    return crc


def crc32(data: bytes) -> int:
    """CRC32 of ``data`` as the document defines it (the whole-packet check).

    zlib computes the same reflected polynomial but complements the register on the way in and
    out; passing the complemented init and complementing the result cancels both.
    """
    return ~zlib.crc32(data, ~_CRC32_INIT_REFLECTED & 0xFFFFFFFF) & 0xFFFFFFFF
