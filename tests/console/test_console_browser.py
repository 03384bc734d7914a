"""The console of a real ``gimbaltrack track`` run in a headless Chromium: the view moves, a box
dragged over the subject (standing still while another thing crosses the picture, which the
motion detector may take first) restarts tracking on it, Record puts the camera's record command on the
bus, Pause puts zero speed then release on it. The page's screenshot goes to the test's folder
(``GIMBALTRACK_CONSOLE_SCREENSHOT=docs/console.png`` writes the docs' one)."""
from __future__ import annotations

import json
import os
import shutil
import time
from pathlib import Path


from gimbal.client import SPEED_RELEASE
from gimbal.messages.camera import CameraActionCode
from pipelines.outputs.telemetry import read_telemetry
from tests.console.browser import chromium, drag, element_image, require_browser
from tests.console.http_helpers import request
from tests.console.track_run import ConsoleRun, crossing, standing, subject_box
from tests.support import wait_until
from tests.track.helpers import SIZE, decoded, host_commands, speed_commands


def test_watch_pick_record_and_pause_from_the_browser(tmp_path: Path) -> None:
    require_browser()
    run = ConsoleRun(tmp_path, position=standing, other=crossing)

    def state() -> dict:
        return json.loads(request(run.port, "GET", "/api/state")[2])

    try:
        with chromium(tmp_path / "profile") as driver:
            driver.get(run.url)
            view = driver.find_element("id", "stream")
            status = driver.find_element("id", "status")
            assert wait_until(lambda: driver.execute_script("return arguments[0].naturalWidth", view) > 0, 30)
            assert wait_until(lambda: "of " in status.text and "–" not in status.text.split("frame")[1][:4], 15)
            first = element_image(view)
            time.sleep(0.5)
            changed = (abs(element_image(view).astype(int) - first.astype(int)).max(axis=2) > 40).mean()
            assert changed > 0.001, f"the view did not move ({changed:.3%} of its pixels changed)"

            band = driver.find_element("id", "band")
            scale = band.rect["width"] / SIZE[0]
            x, y, w, h = subject_box(0, standing)
            drag(driver, band, (x * scale, y * scale), ((x + w) * scale, (y + h) * scale))
            assert wait_until(lambda: state()["state"] == "tracking", 10)
            driver.find_element("id", "record").click()
            assert wait_until(lambda: state()["recording"]["on"] and "on" in status.text, 10)
            time.sleep(0.5)
            shot = tmp_path / "console.png"
            driver.save_screenshot(str(shot))
            if os.environ.get("GIMBALTRACK_CONSOLE_SCREENSHOT"):
                shutil.copyfile(shot, os.environ["GIMBALTRACK_CONSOLE_SCREENSHOT"])
            driver.find_element("id", "pause").click()
            assert wait_until(lambda: state()["state"] == "paused" and "paused" in status.text, 10)
            driver.execute_script("window.confirm = () => true")
            driver.find_element("id", "stop").click()
            code, _, stderr = run.finish()
    finally:
        run.kill()
    assert code == 0, stderr
    lines = read_telemetry(run.out / "telemetry.jsonl")
    selected = [(line, a) for line in lines for a in line.get("operator", []) if a["action"] == "select"]
    assert len(selected) == 1
    line, select = selected[0]
    assert all(abs(a - b) <= 3 for a, b in zip(select["box"], subject_box(0, standing))), select
    assert line["state"] == "tracking" and all(abs(a - b) <= 3 for a, b in zip(line["box"], select["box"]))
    records = decoded(run.out / "can.log")
    sent = host_commands(records)
    assert next(r["fields"]["action"] for r in sent if r["name"] == "camera_action") == CameraActionCode.START_RECORDING
    speeds = speed_commands(records)
    release = next(i for i, s in enumerate(speeds) if s.ctrl == SPEED_RELEASE)  # the pause's
    assert speeds[release].zero and speeds[release - 1].zero
    assert [line["state"] for line in lines].count("paused") > 0
