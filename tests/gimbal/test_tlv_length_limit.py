"""A TLV's LENGTH is one byte (sections 2.3.4.12 and 2.3.4.16: ID + LENGTH + VALUE), so a value of
255 bytes is the longest one that fits."""
from __future__ import annotations

import pytest

from gimbal.errors import RangeError
from gimbal.messages import Tlv
from gimbal.messages.base import decode_tlvs


def test_a_255_byte_value_fits_and_round_trips() -> None:
    tlv = Tlv(0x00, bytes(range(255)))
    encoded = tlv.encode()
    assert encoded[:2] == b"\x00\xff" and len(encoded) == 257
    assert decode_tlvs(encoded, "test") == (tlv,)


def test_a_256_byte_value_is_refused() -> None:
    with pytest.raises(RangeError):
        Tlv(0x00, bytes(256)).encode()
