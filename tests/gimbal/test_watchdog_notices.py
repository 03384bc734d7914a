"""What a run says about the link: one line per episode, the report line, the exit status's test."""
from __future__ import annotations

from gimbal.other_hosts import OtherHostsSeen
from gimbal.watchdog import DEGRADED, DISENGAGED, ENGAGED, BusHealth
from pipelines.loop.link import LinkNotices, link_degraded, link_health, link_report

NOBODY = OtherHostsSeen()


def health(state: str = ENGAGED, episodes: int = 0, disengagements: int = 0, unanswered: int = 0,
           unreachable_s: float = 0.0, late: int = 0) -> BusHealth:
    return BusHealth(state, 0.0, unanswered, late, unanswered + late, 0, unreachable_s, episodes, disengagements)


def test_each_episode_is_said_once_and_the_return_is_said_with_a_restore() -> None:
    said: list[str] = []
    notices = LinkNotices(3.0, said.append)
    assert not notices.update(health(), NOBODY, 1)
    assert not notices.update(health(DEGRADED, 1, unanswered=3), NOBODY, 2)
    assert not notices.update(health(DEGRADED, 1, unanswered=9), NOBODY, 3)  # same episode: silent
    assert not notices.update(health(DISENGAGED, 1, 1, unanswered=80), NOBODY, 90)
    assert not notices.update(health(DISENGAGED, 1, 1, unanswered=90), NOBODY, 91)
    assert notices.update(health(DEGRADED, 1, 1, unanswered=95), NOBODY, 150)  # taken back
    assert not notices.update(health(ENGAGED, 1, 1, unanswered=95), NOBODY, 180)
    assert not notices.update(health(DEGRADED, 2, 1, unanswered=97), NOBODY, 200)
    assert [line.split(":")[0] for line in said] == ["frame 2", "frame 90", "frame 150", "frame 200"]
    assert "3 speed commands without a reply" in said[0]
    assert "no reply for 3 s: the gimbal is stopped and released" in said[1]
    assert "taken back" in said[2]


def test_another_controller_is_said_once() -> None:
    said: list[str] = []
    notices = LinkNotices(3.0, said.append)
    other = OtherHostsSeen(commands=4, control=4, first_control=1.0, names={"speed_control": 4})
    notices.update(health(), other, 7)
    notices.update(health(), OtherHostsSeen(40, 40, 1.0, {"speed_control": 40}), 8)
    assert said == ["frame 7: another host is driving this gimbal too (4 speed_control): two controllers fight over it"]


def test_report_lines_and_exit_status() -> None:
    clean = link_health(health(), NOBODY)
    assert link_report(clean, 200) == "gimbal link: clean, 0 of 200 speed commands unanswered"
    assert not link_degraded(clean)
    slow = link_health(health(late=190), NOBODY)
    assert link_report(slow, 200).endswith("0 of 200 speed commands unanswered, 190 answered late")
    bad = link_health(health(ENGAGED, 1, 1, unanswered=130, unreachable_s=5.06), NOBODY)
    assert link_report(bad, 400) == ("gimbal link: degraded (1 episode, released 1 time): unreachable 5.1 s, "
                                     "130 of 400 speed commands unanswered")
    assert link_degraded(bad)
    shared = link_health(health(), OtherHostsSeen(3, 2, 1.0, {"speed_control": 2, "get_angles": 1}))
    assert link_degraded(shared)
    assert link_report(shared, 10).endswith("; another host sent 2 speed_control, 1 get_angles")


class Camera:
    """What the Recorder uses of a client: record start/stop and the camera's status."""

    def __init__(self) -> None:
        self.recording = False
        self.starts = 0

    def start_recording(self) -> None:
        self.recording, self.starts = True, self.starts + 1

    def stop_recording(self) -> None:
        self.recording = False

    def camera_status(self) -> bool:
        return self.recording


def test_taking_the_gimbal_back_restarts_a_recording_the_camera_stopped() -> None:
    from pipelines.loop.recording import Recorder

    camera = Camera()
    recorder = Recorder(camera, requested=True)  # type: ignore[arg-type]
    recorder.on_acquired()
    recorder.restore()  # still recording: nothing sent
    assert camera.starts == 1 and "restarts" not in recorder.status
    camera.recording = False  # the gimbal was power-cycled while silent
    recorder.restore()
    assert camera.starts == 2 and recorder.status["restarts"] == 1 and recorder.status["start_confirmed"]
    recorder.stop()
    recorder.restore()  # stopped on purpose: left stopped
    assert camera.starts == 2
