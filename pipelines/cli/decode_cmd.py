"""``gimbaltrack decode``: DJI R SDK packets (hex or a CAN log) -> one JSON object per line."""
from __future__ import annotations

import argparse
import json
import re
import sys
from contextlib import closing
from typing import Any, TextIO

from gimbal.log_decode import GIMBAL_TO_HOST, HOST_TO_GIMBAL, LogDecoder
from gimbal.transport import HOST_RX_ID, HOST_TX_ID
from pipelines.cli.common import CliError, parse_int
from pipelines.cli.firmware_opts import add_legacy_order_option
from pipelines.cli.log_input import STDIN, STDIN_FORMATS, LogFrames

_DIRECTION_ALIASES = {"host": HOST_TO_GIMBAL, "gimbal": GIMBAL_TO_HOST, HOST_TO_GIMBAL: HOST_TO_GIMBAL,
                      GIMBAL_TO_HOST: GIMBAL_TO_HOST}
_SEPARATORS = re.compile(r"[\s:,]+|0[xX](?=[0-9a-fA-F])")


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "decode", help="decode DJI R SDK packets from hex or a CAN log into JSON lines",
        description="Decode DJI R SDK packets into one JSON object per packet (document field names, "
        "raw wire values). Anything that does not decode is reported with an 'error' key and the raw "
        "bytes. Exits 0 whenever the input could be read, whatever it held; a log whose last line "
        "is cut short (a recorder stopped mid-write) is read up to it, with a warning.",
        epilog="examples:\n  gimbaltrack decode out/track/can.log\n"
        "  candump -L can0 | gimbaltrack decode -\n"
        "  gimbaltrack decode --hex 'AA 1A 00 03 00 00 00 00 22 11 A2 42 0E 00 20 00 30 00 40 00 01 14 7B 40 97 BE'",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    source = parser.add_mutually_exclusive_group(required=True)
    source.add_argument("log", nargs="?", help="CAN log in any format python-can reads "
                        "(candump .log, .asc, .blf, .csv, .trc, .db; .gz of those), or - for standard input")
    source.add_argument("--hex", action="append", metavar="BYTES",
                        help="packet bytes in hex, spaces/colons optional, several packets allowed; "
                        "repeat the option for more")
    parser.add_argument("--format", choices=sorted(STDIN_FORMATS),
                        help="format of standard input (default: log, candump -L's); a file's comes from its suffix")
    parser.add_argument("--direction", choices=sorted(_DIRECTION_ALIASES),
                        help="direction of --hex bytes (default: inferred per packet from the reply bit)")
    parser.add_argument("--tx-id", type=parse_int, default=HOST_TX_ID,
                        help=f"CAN id the host sends on (default 0x{HOST_TX_ID:03X})")
    parser.add_argument("--rx-id", type=parse_int, default=HOST_RX_ID,
                        help=f"CAN id the gimbal answers on (default 0x{HOST_RX_ID:03X})")
    add_legacy_order_option(parser)
    parser.set_defaults(func=run)


def parse_hex(text: str) -> bytes:
    """Bytes from hex text; whitespace, colons, commas and 0x prefixes are ignored."""
    digits = _SEPARATORS.sub("", text)
    if not digits:
        raise CliError("--hex: no hex digits in an argument")
    if len(digits) % 2:
        raise CliError(f"--hex: odd number of hex digits ({len(digits)})")
    try:
        return bytes.fromhex(digits)
    except ValueError:
        bad = next(c for c in digits if c not in "0123456789abcdefABCDEF")
        raise CliError(f"--hex: {bad!r} is not a hex digit") from None


def run(args: argparse.Namespace, out: TextIO | None = None) -> int:
    out = out or sys.stdout
    decoder = LogDecoder(args.tx_id, args.rx_id, args.legacy_order)
    if args.hex is not None:
        if args.format:
            raise CliError("--format applies to - (standard input) only, not to --hex")
        direction = _DIRECTION_ALIASES[args.direction] if args.direction else None
        data = b"".join(parse_hex(text) for text in args.hex)
        _emit(decoder.feed_bytes(data, direction), out)
        _emit(decoder.finish(), out)
        return 0
    if args.direction:
        raise CliError("--direction applies to --hex only; a log's directions come from its CAN ids")
    last = None
    live = args.log == STDIN  # a pipe from candump: each packet is shown as it arrives
    with closing(LogFrames(args.log, "decode", args.format)) as frames:
        for frame in frames:
            last = frame.timestamp
            _emit(decoder.feed_frame(frame), out)
            if live:
                out.flush()
    _emit(decoder.finish(last), out)  # a frame unreadable part way: the packets read so far come first
    frames.check()
    return 0


def _emit(records: list[dict[str, Any]], out: TextIO) -> None:
    for record in records:
        out.write(json.dumps(record) + "\n")

