"""The browser tests say why they cannot run: under CI a missing Chromium, chromedriver or
Selenium fails them with the reason (scripts/test.sh installs them), elsewhere skips them; and
their modules load without Selenium, so that reason is what pytest shows."""
from __future__ import annotations

import importlib
import sys

import pytest

from tests.console import browser

BROWSER_TESTS = ("tests.console.test_console_browser", "tests.console.test_console_page")


def _without_selenium(monkeypatch: pytest.MonkeyPatch) -> None:
    for name in [n for n in sys.modules if n == "selenium" or n.startswith("selenium.")]:
        monkeypatch.delitem(sys.modules, name)
    monkeypatch.setitem(sys.modules, "selenium", None)  # import selenium raises ImportError


def test_the_browser_test_modules_load_without_selenium(monkeypatch: pytest.MonkeyPatch) -> None:
    _without_selenium(monkeypatch)
    for module in BROWSER_TESTS:
        monkeypatch.delitem(sys.modules, module, raising=False)
        importlib.import_module(module)


@pytest.mark.parametrize("missing", ["chromium", "chromedriver", "selenium"])
def test_a_missing_browser_fails_under_ci_with_the_reason(monkeypatch: pytest.MonkeyPatch, missing: str) -> None:
    real_which = browser.shutil.which
    if missing == "selenium":
        _without_selenium(monkeypatch)
    else:
        monkeypatch.setattr(browser.shutil, "which",
                            lambda name: None if name.startswith(missing) else real_which(name) or f"/usr/bin/{name}")
    monkeypatch.setenv("CI", "true")
    with pytest.raises(pytest.fail.Exception) as failed:
        browser.require_browser()
    assert "chromium and chromium-driver and the selenium package" in str(failed.value)
    assert "missing: " in str(failed.value) and missing in str(failed.value)
    monkeypatch.delenv("CI")
    with pytest.raises(pytest.skip.Exception):
        browser.require_browser()
