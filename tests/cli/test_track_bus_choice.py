"""``gimbaltrack track`` with no -i: python-can's configuration (CAN_* variables, ~/.canrc) when one
names an interface, else the built-in simulated gimbal; one stderr line says which. A broken
configuration is a one-line error, for every command that reads it."""
from __future__ import annotations

import json
from pathlib import Path

import can
import pytest

from gimbal.sim import SimConfig, SimulatedGimbal
from pipelines.cli import main
from tests.track.helpers import drifting, make_clip, roi_at


VARIABLES = ("CAN_INTERFACE", "CAN_CHANNEL", "CAN_BITRATE", "CAN_CONFIG")


@pytest.fixture
def no_configuration(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> Path:
    """No can.rc, no CAN_* variables, a HOME without ~/.canrc; that HOME."""
    home = tmp_path / "home"
    home.mkdir()
    monkeypatch.setattr(can, "rc", {})
    monkeypatch.setenv("HOME", str(home))
    for name in VARIABLES:
        monkeypatch.delenv(name, raising=False)
    return home


def track(clip: Path, out: Path, *extra: str) -> int:
    """``gimbaltrack track`` without --quiet, which leaves the bus line out."""
    return main(["track", str(clip), "--out", str(out), "--roi", roi_at(drifting), "--no-video", *extra])


def first_line(err: str) -> str:
    return err.splitlines()[0] if err else ""  # a progress line may follow it


@pytest.fixture(scope="module")
def clip(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return make_clip(tmp_path_factory.mktemp("clip") / "clip.avi", 20, drifting)


def test_a_canrc_naming_a_bus_drives_the_gimbal_on_it(no_configuration: Path, clip: Path, channel: str,
                                                      tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (no_configuration / ".canrc").write_text(f"[default]\ninterface = virtual\nchannel = {channel}\n")
    with SimulatedGimbal(can.Bus(interface="virtual", channel=channel), SimConfig(), shutdown_bus=True) as gimbal:
        assert track(clip, tmp_path / "out") == 0
        yaw = gimbal.state().attitude[0]
    assert first_line(capsys.readouterr().err) == (f"gimbaltrack track: bus: virtual channel {channel}, from "
                                                   "python-can's configuration (-i picks another)")
    assert abs(yaw) > 0.5  # the gimbal on the configured bus turned after the drifting subject


def test_the_variables_name_the_bus_too(no_configuration: Path, clip: Path, channel: str, tmp_path: Path,
                                        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setenv("CAN_INTERFACE", "virtual")
    monkeypatch.setenv("CAN_CHANNEL", channel)
    with SimulatedGimbal(can.Bus(interface="virtual", channel=channel), SimConfig(), shutdown_bus=True) as gimbal:
        assert track(clip, tmp_path / "out") == 0
        assert abs(gimbal.state().attitude[0]) > 0.5
    assert f"bus: virtual channel {channel}, from python-can's configuration" in capsys.readouterr().err


def test_without_configuration_the_simulator_is_used_and_named(no_configuration: Path, clip: Path,
                                                               tmp_path: Path,
                                                               capsys: pytest.CaptureFixture[str]) -> None:
    assert track(clip, tmp_path / "out") == 0
    out, err = capsys.readouterr()
    assert first_line(err) == ("gimbaltrack track: bus: the built-in simulated gimbal (no -i, and python-can's "
                               "configuration names no interface)")
    assert "bus built-in simulated gimbal" in out
    assert track(clip, tmp_path / "out", "--quiet") == 0
    assert capsys.readouterr().err == ""


def test_a_configured_interface_python_can_lacks_is_an_error_not_the_simulator(
        no_configuration: Path, clip: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setenv("CAN_INTERFACE", "nosuchbus")
    assert track(clip, tmp_path / "out") == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and 'unknown CAN interface: Unknown interface type "nosuchbus"' in err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("command", [["gimbal", "angles"], ["track", "CLIP", "--roi", "1,1,8,8"]])
@pytest.mark.parametrize("variable, canrc, words", [
    ("{", None, "CAN_CONFIG must be a JSON object (python-can's configuration), not '{'"),
    ("[1]", None, "CAN_CONFIG must be a JSON object (python-can's configuration), not '[1]'"),
    (None, "interface = virtual\n", "python-can's configuration file is unreadable: File contains no section headers."),
])
def test_a_broken_configuration_is_one_line(command: list[str], variable: str | None, canrc: str | None,
                                            words: str, no_configuration: Path, clip: Path, tmp_path: Path,
                                            monkeypatch: pytest.MonkeyPatch,
                                            capsys: pytest.CaptureFixture[str]) -> None:
    if variable is not None:
        monkeypatch.setenv("CAN_CONFIG", variable)
    if canrc is not None:
        (no_configuration / ".canrc").write_text(canrc)
    argv = [str(clip) if arg == "CLIP" else arg for arg in command]
    assert main([*argv, *(["--out", str(tmp_path / "out")] if command[0] == "track" else [])]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and words in err, err
    assert not (tmp_path / "out").exists()


def test_config_names_the_simulator_as_the_default_bus(no_configuration: Path, channel: str,
                                                       monkeypatch: pytest.MonkeyPatch,
                                                       capsys: pytest.CaptureFixture[str]) -> None:
    """``gimbaltrack config`` says what ``track`` would drive: the simulator when nothing names a bus."""
    monkeypatch.chdir(no_configuration)  # no ./gimbaltrack.toml
    assert main(["config", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["[bus].interface"] == {"value": "sim", "source": "default"}
    monkeypatch.setenv("CAN_INTERFACE", "virtual")
    assert main(["config", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["[bus].interface"] == {"value": "virtual",
                                                                      "source": "python-can configuration"}
