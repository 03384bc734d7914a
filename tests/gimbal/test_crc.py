"""CRC16/CRC32 of the DJI R SDK: known answers and a bitwise cross-check of the fast versions."""
from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from gimbal.crc import crc16, crc32

DOC_EXAMPLE = bytes.fromhex("AA 1A 00 03 00 00 00 00 22 11 A2 42 0E 00 20 00 30 00 40 00 01 14 7B 40 97 BE")


def reflect(value: int, width: int) -> int:
    return int(f"{value:0{width}b}"[::-1], 2)


def rocksoft(data: bytes, width: int, poly: int, init: int, refin: bool, refout: bool, xorout: int) -> int:
    """The textbook bit-at-a-time CRC, written from the Rocksoft model's parameters alone."""
    top, mask = 1 << (width - 1), (1 << width) - 1
    crc = init
    for byte in data:
        crc ^= (reflect(byte, 8) if refin else byte) << (width - 8)
        for _ in range(8):
            crc = ((crc << 1) ^ poly) & mask if crc & top else (crc << 1) & mask
    return (reflect(crc, width) if refout else crc) ^ xorout


def crc16_reference(data: bytes) -> int:
    # Document section 3.2, Figure 40.
    return rocksoft(data, 16, 0x8005, 0xC55C, True, True, 0x0000)


def crc32_reference(data: bytes) -> int:
    return rocksoft(data, 32, 0x04C11DB7, 0xC55C0000, True, True, 0x00000000)


def test_document_example_crcs() -> None:
    # Document section 3.4: the CRC tools print 0x42a2 and 0xbe97407b for the section 3.3 command.
    assert crc16(DOC_EXAMPLE[:10]) == 0x42A2
    assert crc32(DOC_EXAMPLE[:-4]) == 0xBE97407B
    assert crc16_reference(DOC_EXAMPLE[:10]) == 0x42A2
    assert crc32_reference(DOC_EXAMPLE[:-4]) == 0xBE97407B


def test_check_values_of_the_models() -> None:
    """The standard check input '123456789', computed by the reference implementations."""
    assert crc16(b"123456789") == crc16_reference(b"123456789") == 0x2752
    assert crc32(b"123456789") == crc32_reference(b"123456789") == 0xE4D9DC14


def test_empty_input_returns_the_reflected_init() -> None:
    assert crc16(b"") == reflect(0xC55C, 16) == 0x3AA3
    assert crc32(b"") == reflect(0xC55C0000, 32) == 0x3AA3


def test_not_the_standard_crcs() -> None:
    """Guard against a silent fallback to CRC-16/ARC or plain zlib CRC-32."""
    import zlib
    assert crc16(b"123456789") != 0xBB3D
    assert crc32(b"123456789") != zlib.crc32(b"123456789")


@given(st.binary(max_size=300))
def test_crc16_table_matches_bitwise_reference(data: bytes) -> None:
    assert crc16(data) == crc16_reference(data)


@given(st.binary(max_size=300))
def test_crc32_zlib_matches_bitwise_reference(data: bytes) -> None:
    assert crc32(data) == crc32_reference(data)


@given(st.binary(min_size=1, max_size=64), st.integers(0, 63), st.integers(0, 7))
def test_single_bit_errors_are_detected(data: bytes, index: int, bit: int) -> None:
    index %= len(data)
    flipped = bytearray(data)
    flipped[index] ^= 1 << bit
    assert crc16(bytes(flipped)) != crc16(data)
    assert crc32(bytes(flipped)) != crc32(data)
