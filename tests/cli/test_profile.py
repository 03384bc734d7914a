"""Rig profiles (``--profile FILE`` or ./gimbaltrack.toml) and ``gimbaltrack config``."""
from __future__ import annotations

import json
import random
from collections import Counter
import subprocess
from pathlib import Path

import can
import pytest

from pipelines.cli import main
from pipelines.cli.app import build_parser
from pipelines.cli.common import CliError
from pipelines.cli.profile import apply_profile, profile_path, read_profile
from gimbal.client import GimbalClient
from gimbal.errors import GimbalError
from tests.support import ROOT, cli_command, free_udp_port, subprocess_env, wait_until
from tests.track.helpers import DEMO, DEMO_ROI

RIG = """
[bus]
interface = "udp_multicast"
channel = "239.74.1.2"
tx_id = 0x323
rx_id = 0x322

[gimbal]
invert_yaw = true

[control]
max_speed = 90

[outputs]
video = false
"""


def write(tmp_path: Path, text: str, name: str = "rig.toml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def parsed(*argv: str):
    parser = build_parser()
    path = profile_path(argv)
    if path is not None:
        apply_profile(parser, read_profile(path, parser))
    return parser.parse_args(argv)


def test_a_profile_fills_in_the_options_it_names(tmp_path: Path) -> None:
    args = parsed("track", "clip.mp4", "--profile", str(write(tmp_path, RIG)))
    assert (args.interface, args.channel, args.tx_id, args.rx_id) == ("udp_multicast", "239.74.1.2", 0x323, 0x322)
    assert args.invert_yaw is True and args.invert_pitch is False
    assert args.max_speed == 90.0 and args.no_video is True
    assert args.rate == 25.0  # not in the profile: the option's own default


def test_the_command_line_wins_over_the_profile(tmp_path: Path) -> None:
    args = parsed("track", "clip.mp4", f"--profile={write(tmp_path, RIG)}", "-i", "sim", "--max-speed", "30")
    assert (args.interface, args.max_speed, args.tx_id) == ("sim", 30.0, 0x323)


def test_the_profile_reaches_nested_gimbal_commands_and_not_the_simulator(tmp_path: Path) -> None:
    rig = str(write(tmp_path, RIG))
    assert parsed("gimbal", "angles", "--profile", rig).interface == "udp_multicast"
    assert parsed("gimbal", "--profile", rig, "angles", "-i", "sim").interface == "sim"
    sim = parsed("sim", "--profile", rig)  # the device side keeps its own bus and ids
    assert (sim.interface, sim.tx_id) == ("udp_multicast", 0x223) and sim.channel is None


def test_gimbaltrack_toml_in_the_working_folder_is_read(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    write(tmp_path, RIG, "gimbaltrack.toml")
    monkeypatch.chdir(tmp_path)
    assert parsed("track", "clip.mp4").channel == "239.74.1.2"
    other = write(tmp_path, "[bus]\nchannel = \"239.74.9.9\"\n", "other.toml")
    assert parsed("track", "clip.mp4", "--profile", str(other)).channel == "239.74.9.9"


@pytest.mark.parametrize(("text", "expected"), [
    ("[bus]\nport = 3\n", "unknown key [bus].port (known in [bus]: interface, channel, bitrate, tx_id, rx_id)"),
    ("[rig]\nname = 'x'\n", "unknown section [rig]"),
    ("bus = 3\n", "bus must be a table"),
    ("[control]\nmax_speed = 'fast'\n", "[control].max_speed: must be a number, not 'fast'"),
    ("[control]\ncontroller = 'pd'\n", "[control].controller: 'pd' is not one of"),
    ("[gimbal]\ninvert_yaw = 'no'\n", "[gimbal].invert_yaw: must be true or false, not 'no'"),
    ("[bus]\ntx_id = 0x900\n", "[bus].tx_id: not a standard CAN id"),
    ("[control\n", "not valid TOML"),
])
def test_a_bad_profile_is_one_line_naming_the_key_and_the_file(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                               text: str, expected: str) -> None:
    path = write(tmp_path, text)
    with pytest.raises(SystemExit) as exit_:
        main(["track", "clip.mp4", "--profile", str(path), "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert exit_.value.code == 2 and err.count("\n") == 1 and "Traceback" not in err
    assert f"profile {path}: " in err and expected in err
    assert not (tmp_path / "out").exists()


def test_a_missing_or_folder_profile_is_named(tmp_path: Path) -> None:
    parser = build_parser()
    with pytest.raises(CliError, match="no such file"):
        read_profile(tmp_path / "none.toml", parser)
    with pytest.raises(CliError, match="is a folder"):
        read_profile(tmp_path, parser)


def test_a_commands_own_range_check_names_the_profile_key(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = write(tmp_path, "[control]\nmax_speed = 900\n")
    assert main(["track", str(DEMO), "--profile", str(path), "--out", str(tmp_path / "out")]) == 2
    assert "--max-speed takes 0 < DEG_S <= 360" in (err := capsys.readouterr().err)
    assert f"(from [control].max_speed in {path})" in err
    assert main(["track", str(DEMO), "--profile", str(path), "--max-speed", "400", "--out", str(tmp_path / "o")]) == 2
    assert "from [control]" not in capsys.readouterr().err  # the command line said it, not the profile


def test_config_says_where_each_setting_comes_from(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                   monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)  # no ./gimbaltrack.toml
    monkeypatch.setenv("CAN_INTERFACE", "virtual")
    monkeypatch.setenv("CAN_CHANNEL", "vcan7")
    monkeypatch.setenv("HOME", str(tmp_path))  # no ~/.canrc of the machine's
    path = write(tmp_path, "[bus]\nchannel = \"239.74.1.2\"\n[outputs]\nvideo = false\n")
    assert main(["config", "--profile", str(path), "--json"]) == 0
    settings = json.loads(capsys.readouterr().out)
    assert settings["[bus].channel"] == {"value": "239.74.1.2", "source": f"profile {path}"}
    assert settings["[bus].interface"] == {"value": "virtual", "source": "python-can configuration"}
    assert settings["[outputs].video"] == {"value": False, "source": f"profile {path}"}
    assert settings["[control].rate"] == {"value": 25.0, "source": "default"}
    assert settings["[bus].tx_id"] == {"value": 0x223, "source": "default"}
    assert main(["config", "--profile", str(path)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert any(line.split() == ["[bus].tx_id", "0x223", "default"] for line in lines)


def wait_for_sim(group: str, port: int, deadline_s: float = 30.0) -> None:
    """Until the simulator process answers (its start, importing OpenCV, takes seconds under load)."""
    with GimbalClient(interface="udp_multicast", channel=group, port=port, tx_id=0x323, rx_id=0x322,
                      timeout=0.3) as client:
        assert wait_until(lambda: _answers(client), deadline_s, step=0.1), "the simulator never answered"


def _answers(client: GimbalClient) -> bool:
    try:
        client.version()
    except GimbalError:
        return False
    return True


def test_a_profile_drives_track_with_no_bus_options_on_the_command_line(tmp_path: Path) -> None:
    port, group = free_udp_port(), f"239.74.{random.randrange(1, 255)}.{random.randrange(1, 255)}"
    env = subprocess_env(port)
    rig = write(tmp_path, RIG.replace("239.74.1.2", group))
    sim = subprocess.Popen(cli_command("sim", "-i", "udp_multicast", "-c", group, "--tx-id", "0x323",
                                       "--rx-id", "0x322"), stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                           text=True, cwd=ROOT, env=env)
    try:
        wait_for_sim(group, port)
        done = subprocess.run(cli_command("track", str(DEMO), "--roi", DEMO_ROI, "--max-frames", "40", "--quiet",
                                          "--profile", str(rig), "--out", str(tmp_path / "out")),
                              capture_output=True, text=True, timeout=120, cwd=ROOT, env=env)
    finally:
        sim.terminate()
        sim.communicate(timeout=30)
    assert done.returncode == 0, done.stderr
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert "udp_multicast" in json.dumps(summary["bus"]) and not (tmp_path / "out" / "annotated.avi").exists()
    ids = Counter(frame.arbitration_id for frame in can.LogReader(str(tmp_path / "out" / "can.log")))
    assert ids[0x323] > 40 and ids[0x322] > 40 and set(ids) == {0x322, 0x323}  # the profile's ids, answered


def test_config_names_a_broken_python_can_configuration(capsys: pytest.CaptureFixture[str],
                                                        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("CAN_CONFIG", "[1]")
    assert main(["config"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "CAN_CONFIG must be a JSON object" in err
