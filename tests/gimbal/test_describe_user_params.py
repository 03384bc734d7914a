"""Naming user parameters (section 2.3.4.12, Figure 23): only the document's three 1-byte IDs get a
name; any other ID, or a known ID with a value of another length, is shown as raw hex."""
from __future__ import annotations

import pytest

from gimbal.messages import Tlv
from gimbal.messages.tlv_params import describe_user_param


@pytest.mark.parametrize("tlv,described", [
    (Tlv(0x00, b"\x02"), {"param_table": 2}),
    (Tlv(0x22, b"\x08"), {"roll360_mode": "two_axis"}),
    (Tlv(0x23, b"\x01"), {"motors_off": 1}),
    (Tlv(0x42, b"\x01"), {"0x42": "01"}),
    (Tlv(0x01, b"\x00"), {"0x01": "00"}),
    (Tlv(0x23, b"\x01\x00"), {"0x23": "0100"}),
    (Tlv(0x00, b""), {"0x00": ""}),
])
def test_known_ids_are_named_and_the_rest_shown_raw(tlv: Tlv, described: dict[str, int | str]) -> None:
    assert describe_user_param(tlv) == described
