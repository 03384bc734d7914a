"""What every ``gimbaltrack`` subcommand shares: one-line errors and the python-can bus options."""
from __future__ import annotations

import argparse
import math
import os
from pathlib import Path

#: Exit status of a run stopped by Ctrl-C (128 + SIGINT, as a shell reports it).
EXIT_INTERRUPTED = 130


class CliError(Exception):
    """A user-facing failure: printed as one line, exit code ``exit_code``."""

    def __init__(self, message: str, exit_code: int = 2) -> None:
        super().__init__(message)
        self.exit_code = exit_code


def make_out_dir(out: Path) -> None:
    """Create an ``--out`` folder before any work, so that a bad one fails at once, in one line."""
    if out.exists() and not out.is_dir():
        raise CliError(f"--out {out} is a file, not a folder")
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise CliError(f"cannot create output folder {out}: {exc.strerror}") from None
    if not os.access(out, os.W_OK | os.X_OK):  # read-only (a mount, a mode): say so now, not after the run
        raise CliError(f"cannot write in output folder {out}: read-only or no permission")


def existing_dir(text: str) -> Path:
    """An existing folder (``--model-dir``): a typo must not quietly mean "no models", nor an empty
    path the current folder."""
    if not text.strip():
        raise argparse.ArgumentTypeError("an empty path (use . for the current folder)")
    path = Path(text)
    if path.exists() and not path.is_dir():
        raise argparse.ArgumentTypeError(f"{text!r} is a file, not a folder")
    if not path.is_dir():
        raise argparse.ArgumentTypeError(f"no such folder: {text!r}")
    return path


def existing_file(text: str) -> Path:
    """An existing file (``--groundtruth``): an empty path or a folder is refused by name."""
    if not text.strip():
        raise argparse.ArgumentTypeError("an empty path")
    path = Path(text)
    if path.is_dir():
        raise argparse.ArgumentTypeError(f"{text!r} is a folder, not a file")
    if not path.is_file():
        raise argparse.ArgumentTypeError(f"no such file: {text!r}")
    return path


def out_dir(text: str) -> Path:
    """An ``--out`` folder; an empty one is refused (it would mean the current folder), and so is
    the filesystem root (a run's files scattered among the system's folders)."""
    if not text.strip():
        raise argparse.ArgumentTypeError("an empty path (use . for the current folder)")
    path = Path(text)
    real = Path(os.path.realpath(path))  # not Path.resolve(): a symlink loop raises RuntimeError there
    if real == Path(real.anchor):
        raise argparse.ArgumentTypeError(f"{text!r} is the filesystem root: give the outputs a folder of their own")
    return path


def parse_int(text: str) -> int:
    """An integer in decimal or with a 0x/0o/0b prefix (for ids, SEQ and raw bytes)."""
    try:
        return int(text, 0)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an integer: {text!r}") from None


def parse_seconds(text: str) -> float:
    """A duration in seconds: a finite number, 0 or more."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not 0 <= value < math.inf:
        raise argparse.ArgumentTypeError(f"not a duration in seconds (a finite number, 0 or more): {text!r}")
    return value


def parse_can_id(text: str) -> int:
    """A standard (11-bit) CAN id, decimal or 0x..."""
    value = parse_int(text)
    if not 0 <= value <= 0x7FF:
        raise argparse.ArgumentTypeError(f"not a standard CAN id (0 to 0x7FF): {text!r}")
    return value


def parse_bitrate(text: str) -> int:
    """A bitrate in bit/s, above zero."""
    value = parse_int(text)
    if value <= 0:
        raise argparse.ArgumentTypeError(f"a bitrate is above 0 bit/s, not {text!r}")
    return value


def add_bus_options(parser: argparse.ArgumentParser, default_interface: str | None = None,
                    repeated: bool = False, offers_sim: bool = True, fallback: str | None = None) -> None:
    """python-can's own options; unset values fall back to can.rc, CAN_* variables and ~/.canrc.
    ``offers_sim``: ``-i sim`` (the built-in simulated gimbal) is one of the choices; ``fallback``:
    what the command uses when python-can's configuration names no interface.

    ``repeated`` adds them again to a command whose parent parser has them already: given there
    they win, left out they keep the parent's value (``gimbal -i sim angles`` = ``gimbal angles -i sim``).
    """
    group = parser.add_argument_group("CAN bus (python-can conventions)")
    group.add_argument(
        "-i", "--interface", default=default_interface,
        help="python-can interface (socketcan, slcan, pcan, kvaser, gs_usb, virtual, udp_multicast, ...)"
        + (" or 'sim' for the built-in simulated gimbal" if offers_sim else "")
        + (f" (default: {default_interface})" if default_interface else
           " (default: python-can's configuration" + (f", else {fallback})" if fallback else ")")),
    )
    group.add_argument("-c", "--channel", help="channel, e.g. can0, /dev/ttyACM0, PCAN_USBBUS1, a multicast "
                       "group (not with the simulated gimbal)")
    group.add_argument("-b", "--bitrate", type=parse_bitrate,
                       help="bitrate in bit/s (default: python-can's configuration, else 1000000, the DJI R SDK's "
                       "1 Mbit/s; socketcan's is set with 'ip link'; not with the simulated gimbal)")
    group.add_argument("--tx-id", type=parse_can_id, default=0x223, help="CAN id the host sends on (default 0x223)")
    group.add_argument("--rx-id", type=parse_can_id, default=0x222, help="CAN id the host listens on (default 0x222)")
    if repeated:
        suppress_defaults(group._group_actions)


def suppress_defaults(actions: list[argparse.Action]) -> None:
    """Let a subcommand's copy of an option leave the parent's value alone when not given."""
    for action in actions:
        action.default = argparse.SUPPRESS
