"""The console's page in a real (headless) browser, against a fake loop: the view moves, a drag
selects a box in source pixels, the buttons reach the operator."""
from __future__ import annotations

import time


from tests.console.browser import chromium, drag, element_image, touch_drag
from tests.console.fakes import SIZE, FrameFeeder, start_console
from tests.support import wait_until


def test_the_page_shows_the_live_view_and_sends_what_the_operator_does(tmp_path) -> None:
    server, sink, operator = start_console()
    try:
        with FrameFeeder(sink, fps=30), chromium(tmp_path / "profile") as driver:
            driver.get(server.url)
            view = driver.find_element("id", "stream")
            assert wait_until(lambda: driver.execute_script("return arguments[0].naturalWidth", view) > 0, 15)
            first = element_image(view)
            time.sleep(0.3)
            changed = (abs(element_image(view).astype(int) - first.astype(int)).max(axis=2) > 40).mean()
            assert changed > 0.01, f"the view did not move ({changed:.2%} of its pixels changed)"
            status = driver.find_element("id", "status")
            assert wait_until(lambda: "tracking" in status.text, 10), status.text
            band = driver.find_element("id", "band")
            scale = band.rect["width"] / SIZE[0]
            drag(driver, band, (200 * scale, 100 * scale), (280 * scale, 220 * scale))
            assert wait_until(lambda: any(c[0] == "select" for c in operator.calls), 5), operator.calls
            x, y, w, h = next(c[1] for c in operator.calls if c[0] == "select")
            assert abs(x - 200) <= 3 and abs(y - 100) <= 3 and abs(w - 80) <= 3 and abs(h - 120) <= 3
            driver.find_element("id", "pause").click()
            driver.find_element("id", "record").click()
            assert wait_until(lambda: ("pause", None) in operator.calls and ("record", True) in operator.calls, 5)
    finally:
        server.stop()
        sink.close()


def test_on_a_phone_a_finger_drags_a_box_and_taps_a_candidate(tmp_path) -> None:
    """A phone-sized window: the page fits its width; a finger's drag selects that box, a tap on a
    candidate (the fake's magenta box at 300,100 50x50) selects the candidate."""
    server, sink, operator = start_console()
    try:
        with FrameFeeder(sink, fps=30), chromium(tmp_path / "profile") as driver:
            driver.set_window_size(400, 850)
            driver.get(server.url)
            view = driver.find_element("id", "stream")
            assert wait_until(lambda: driver.execute_script("return arguments[0].naturalWidth", view) > 0, 15)
            status = driver.find_element("id", "status")
            assert wait_until(lambda: "tracking" in status.text, 10), status.text
            width = driver.execute_script("return window.innerWidth")
            assert driver.execute_script("return document.documentElement.scrollWidth") <= width
            band = driver.find_element("id", "band")
            assert band.rect["width"] <= width
            scale = band.rect["width"] / SIZE[0]
            touch_drag(driver, band, (40 * scale, 60 * scale), (200 * scale, 300 * scale))
            assert wait_until(lambda: any(c[0] == "select" for c in operator.calls), 5), operator.calls
            x, y, w, h = next(c[1] for c in operator.calls if c[0] == "select")
            tolerance = 2 / scale  # a CSS pixel or two, in source pixels
            assert abs(x - 40) <= tolerance and abs(y - 60) <= tolerance, (x, y)
            assert abs(w - 160) <= tolerance and abs(h - 240) <= tolerance, (w, h)
            operator.calls.clear()
            touch_drag(driver, band, (325 * scale, 125 * scale), (325 * scale, 125 * scale))
            assert wait_until(lambda: operator.calls, 5)
            assert operator.calls == [("select", (300.0, 100.0, 50.0, 50.0))]
    finally:
        server.stop()
        sink.close()
