"""The command-line option for a firmware variant that every bus-facing subcommand shares."""
from __future__ import annotations

import argparse

from gimbal.messages.firmware import LEGACY_ORDER_DOCUMENT, LEGACY_ORDERS


def add_legacy_order_option(parser: argparse.ArgumentParser, repeated: bool = False) -> None:
    """``--legacy-order document|ypr``: the axis order of legacy-layout angle replies (see
    docs/protocol.md). ``repeated``: a subcommand's copy that leaves the parent's value alone
    when not given."""
    parser.add_argument("--legacy-order", choices=LEGACY_ORDERS,
                        default=argparse.SUPPRESS if repeated else LEGACY_ORDER_DOCUMENT,
                        help="axis order of legacy angle replies (old firmware, no CmdSet/CmdID): "
                        "'document' yaw, roll, pitch (default), or 'ypr' yaw, pitch, roll as ArduPilot reads them")
