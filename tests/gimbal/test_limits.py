"""One home for each protocol fact: the codec's limits are the ones the client, keep-alive, CLI and
control use, and pushes and replies hand out degrees."""
from __future__ import annotations

import argparse

import pytest

from gimbal import keepalive
from gimbal.errors import RangeError
from gimbal.messages import limits
from gimbal.messages.motion import (
    AnglesReply,
    AxisDegrees,
    PositionControl,
    SpeedControl,
)
from gimbal.messages.telemetry import ParameterPush
from pipelines.cli.gimbal_cmd import register
from pipelines.control import limits as control_limits


def test_the_speed_limit_is_the_documents_in_both_units() -> None:
    assert limits.SPEED_RANGE == (-3600, 3600)
    assert limits.MAX_SPEED_DPS == 360.0
    assert control_limits.PROTOCOL_MAX_SPEED_DPS is limits.MAX_SPEED_DPS
    assert keepalive.MIN_RATE_HZ == 2 / limits.SPEED_COMMAND_LASTS_S == 4.0
    SpeedControl(yaw_speed=3600).validate()
    with pytest.raises(RangeError):
        SpeedControl(yaw_speed=3601).validate()


def test_messages_check_against_the_limits_module() -> None:
    assert PositionControl.RANGES["yaw_angle"] is limits.YAW_ANGLE_RANGE
    assert PositionControl.RANGES["time_for_action"] is limits.TIME_RANGE
    assert SpeedControl.RANGES["pitch_speed"] is limits.SPEED_RANGE


def test_a_parameter_push_hands_out_degrees_when_its_angles_are_valid() -> None:
    push = ParameterPush(ctrl_byte=1, yaw_angle=-1795, roll_angle=3, pitch_angle=-120,
                         yaw_joint_angle=10, roll_joint_angle=-20, pitch_joint_angle=1460)
    assert push.attitude == AxisDegrees(-179.5, 0.3, -12.0)
    assert push.joint == AxisDegrees(1.0, -2.0, 146.0)
    assert push.yaw_angle == -1795  # the raw field stays for the codec
    assert ParameterPush(ctrl_byte=0, yaw_angle=1, roll_angle=2, pitch_angle=3).attitude is None
    assert ParameterPush(ctrl_byte=1, yaw_angle=1, roll_angle=2, pitch_angle=3).joint is None


def test_an_angles_reply_hands_out_degrees() -> None:
    assert AnglesReply(0, 1, 100, -20, 50).degrees == AxisDegrees(10.0, -2.0, 5.0)
    assert AnglesReply(0, 0).degrees is None


def test_the_cli_help_shows_the_documents_ranges() -> None:
    parser = argparse.ArgumentParser()
    register(parser.add_subparsers())
    gimbal = parser._subparsers._group_actions[0].choices["gimbal"]  # type: ignore[union-attr]
    commands = gimbal._subparsers._group_actions[0].choices  # type: ignore[union-attr]
    move, speed = commands["move"].format_help(), commands["speed"].format_help()
    assert "-180..180" in move and "-56..146" in move and "0..25.5" in move
    assert "-360..360" in speed
