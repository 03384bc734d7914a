"""A headless Chromium driven by Selenium, for the console's page: skipped with the reason when
the browser is missing, failed under CI (``scripts/test.sh`` installs it from Debian)."""
from __future__ import annotations

import os
import shutil
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import cv2
import numpy as np
import pytest

CHROMIUM_FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                  "--disable-background-networking", "--disable-component-update", "--disable-sync",
                  "--window-size=1280,900")


def require_browser() -> tuple[str, str]:
    """Chromium's and chromedriver's paths; fails under CI, else skips, when either is missing."""
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    driver = shutil.which("chromedriver")
    try:
        import selenium  # noqa: F401
    except ImportError:
        driver = None
    if chromium is None or driver is None:
        message = ("the console's browser test needs Debian's chromium and chromium-driver and the "
                   "selenium package (scripts/test.sh installs them); missing: "
                   + ", ".join(n for n, p in (("chromium", chromium), ("chromedriver / selenium", driver)) if not p))
        if os.environ.get("CI"):
            pytest.fail(message)
        pytest.skip(message)
    return chromium, driver


@contextmanager
def chromium(profile: Path) -> Iterator:
    """A headless Chromium with a fresh profile in ``profile``."""
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    binary, driver_path = require_browser()
    options = webdriver.ChromeOptions()
    options.binary_location = binary
    for flag in CHROMIUM_FLAGS:
        options.add_argument(flag)
    options.add_argument(f"--user-data-dir={profile}")
    driver = webdriver.Chrome(service=Service(executable_path=driver_path), options=options)
    try:
        yield driver
    finally:
        driver.quit()


def element_image(element) -> np.ndarray:
    """What the browser shows of ``element`` now, as a BGR image."""
    image = cv2.imdecode(np.frombuffer(element.screenshot_as_png, np.uint8), cv2.IMREAD_COLOR)
    assert image is not None
    return image


def drag(driver, element, start: tuple[float, float], end: tuple[float, float]) -> None:
    """Press at ``start``, move to ``end`` and release, in CSS pixels from the element's top left."""
    from selenium.webdriver.common.action_chains import ActionChains

    rect = element.rect
    to_centre = (rect["width"] / 2, rect["height"] / 2)
    x0, y0 = (round(start[0] - to_centre[0]), round(start[1] - to_centre[1]))
    ActionChains(driver).move_to_element_with_offset(element, x0, y0).click_and_hold() \
        .move_by_offset(round((end[0] - start[0]) / 2), round((end[1] - start[1]) / 2)) \
        .move_by_offset(round((end[0] - start[0]) / 2), round((end[1] - start[1]) / 2)).release().perform()


def touch_drag(driver, element, start: tuple[float, float], end: tuple[float, float]) -> None:
    """A finger (a touch pointer, as a phone's) pressed at ``start``, moved to ``end`` and lifted;
    ``start == end`` is a tap. CSS pixels from the element's top left."""
    from selenium.webdriver.common.actions import interaction
    from selenium.webdriver.common.actions.action_builder import ActionBuilder
    from selenium.webdriver.common.actions.pointer_input import PointerInput

    rect = element.rect
    centre = (rect["width"] / 2, rect["height"] / 2)
    at = [(round(x - centre[0]), round(y - centre[1])) for x, y in (start, end)]
    actions = ActionBuilder(driver, mouse=PointerInput(interaction.POINTER_TOUCH, "finger"))
    actions.pointer_action.move_to(element, *at[0]).pointer_down().pause(0.05) \
        .move_to(element, *at[1]).pointer_up()
    actions.perform()
