"""The CAN bus a subcommand talks to a gimbal on: python-can's own, or the built-in simulator."""
from __future__ import annotations

import argparse
import configparser
import json
import os
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import can

from gimbal.sim import SimConfig, SimulatedGimbal, start_in_process
from gimbal.transport import with_default_bitrate
from pipelines.cli.common import CliError

SIM_INTERFACE = "sim"
SIM_WORDS = "built-in simulated gimbal"
NO_INTERFACE = ("no CAN interface configured: pass -i/--interface (socketcan, slcan, pcan, gs_usb, "
                "virtual, udp_multicast, ... or 'sim'), or set CAN_INTERFACE or ~/.canrc")


def bus_options(args: argparse.Namespace) -> dict[str, Any]:
    """``can.Bus`` keyword arguments from -i/-c/-b; unset ones are left out so that can.rc,
    ``CAN_*`` variables and ``~/.canrc`` fill them in (``open_can_bus`` adds the 1 Mbit/s default
    when none of them gives a bitrate)."""
    given = {"interface": args.interface, "channel": args.channel, "bitrate": args.bitrate}
    return {key: value for key, value in given.items() if value is not None}


@contextmanager
def open_host_bus(args: argparse.Namespace) -> Iterator[can.BusABC]:
    """The host's bus for the subcommand; ``-i sim`` starts the simulated gimbal in-process.
    Failures to open become one-line ``CliError``s; the bus is shut down on exit."""
    if args.interface == SIM_INTERFACE:
        with simulated_gimbal(args) as (bus, _):
            yield bus
        return
    bus = open_can_bus(bus_options(args))
    try:
        yield bus
    finally:
        if not bus._is_shutdown:  # already shut down by its user: slcan's second shutdown raises
            bus.shutdown()


def choose_track_bus(args: argparse.Namespace) -> tuple[str, str | None]:
    """``track`` with no -i: python-can's configuration when one names an interface, else the
    built-in simulated gimbal (``args.interface`` becomes 'sim'). Returns the bus in a few words,
    and the line that says which was chosen (None when -i chose): a real gimbal must not sit
    still, unnoticed, because the simulator was driven instead."""
    if args.interface == SIM_INTERFACE:
        return SIM_WORDS, None
    if args.interface is not None:
        return " ".join(str(v) for v in (args.interface, args.channel) if v is not None), None
    config = python_can_config(bus_options(args))
    if config is None:
        refuse_bus_options(args)
        args.interface = SIM_INTERFACE
        return SIM_WORDS, (f"gimbaltrack track: bus: the {SIM_WORDS} (no -i, and python-can's configuration "
                           "names no interface)")
    where = describe(config)
    return where, f"gimbaltrack track: bus: {where}, from python-can's configuration (-i picks another)"


def python_can_config(options: dict[str, Any]) -> dict[str, Any] | None:
    """python-can's configuration (``options``, then can.rc, the CAN_* variables, ~/.canrc), read by
    python-can itself; None when no source names an interface. A broken one is a ``CliError``."""
    try:
        return load_bus_config(options)
    except _NoInterface:
        return None


def load_bus_config(options: dict[str, Any]) -> dict[str, Any]:
    """``can.util.load_config`` with its failures in one line each."""
    _check_config_variable()
    try:
        return can.util.load_config(config=dict(options))
    except can.CanInterfaceNotImplementedError as exc:
        if '"None"' in str(exc):  # python-can's words when no source names an interface
            raise _NoInterface(NO_INTERFACE) from None
        raise CliError(f"cannot open the CAN bus: unknown CAN interface: {_one_line(exc)}") from None
    except configparser.Error as exc:
        raise CliError(f"python-can's configuration file is unreadable: {' '.join(str(exc).split())}") from None


class _NoInterface(CliError):
    """No source of python-can's configuration names an interface."""


def _check_config_variable() -> None:
    """CAN_CONFIG holds a JSON object (python-can would fail on anything else with a traceback)."""
    text = os.environ.get("CAN_CONFIG")
    if text is None:
        return
    try:
        value = json.loads(text)
    except ValueError:
        value = None
    if not isinstance(value, dict):
        raise CliError(f"CAN_CONFIG must be a JSON object (python-can's configuration), not {text!r}")


def describe(config: dict[str, Any]) -> str:
    """A bus configuration in a few words, e.g. 'socketcan channel can0'."""
    return f"{config['interface']} channel {config.get('channel')}"


def open_can_bus(options: dict[str, Any]) -> can.BusABC:
    """``can.Bus(**options)``, at 1 Mbit/s unless a bitrate is given or configured; failures
    become one-line ``CliError``s."""
    config = load_bus_config(options)
    where = describe(config)
    try:  # the configuration read above, whole: can.Bus need not read the files again
        return can.Bus(**with_default_bitrate({**config, "ignore_config": True}))
    except (can.CanError, OSError, ValueError, ImportError, TypeError) as exc:  # TypeError: a missing channel
        raise CliError(f"cannot open the CAN bus ({where}): {_one_line(exc)}") from None


@contextmanager
def simulated_gimbal(args: argparse.Namespace) -> Iterator[tuple[can.BusABC, SimulatedGimbal]]:
    """(host bus, simulated gimbal) for ``-i sim``: the simulator listens on --tx-id and answers
    on --rx-id, with the faults of ``--sim-faults`` where a command offers it; both are stopped on exit. A channel or bitrate given with it is refused: whoever
    gives one means a real bus and forgot -i."""
    refuse_bus_options(args)
    check_sim_ids(args)
    host_bus, sim = start_in_process(SimConfig(rx_id=args.tx_id, tx_id=args.rx_id), getattr(args, "sim_faults", None))
    try:
        yield host_bus, sim
    finally:
        sim.stop()
        host_bus.shutdown()


def refuse_bus_options(args: argparse.Namespace) -> None:
    """A channel or bitrate given for the simulated gimbal: whoever gives one means a real bus."""
    if args.channel is not None or args.bitrate is not None:
        raise CliError("the built-in simulated gimbal (-i sim, and track's default) takes no -c/--channel or "
                       "-b/--bitrate: give -i with a python-can interface for a real bus")


def check_sim_ids(args: argparse.Namespace) -> None:
    """The simulated gimbal (``sim``, ``-i sim``) listens on --tx-id and answers on --rx-id: one
    id for both is refused up front (it once ended in "the gimbal does not answer", exit 1)."""
    if args.tx_id == args.rx_id:
        raise CliError(f"--tx-id and --rx-id must differ (both 0x{args.tx_id:03X})")


def _one_line(exc: BaseException) -> str:
    text = str(exc).strip() or type(exc).__name__
    return text.splitlines()[0]
