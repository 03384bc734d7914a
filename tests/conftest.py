"""Fixtures shared by the whole suite."""
from __future__ import annotations

import os
import uuid
from collections.abc import Iterator
from pathlib import Path

import can
import pytest

from tests.gimbal.scripted_peer import ScriptedPeer
from tracker.evaluation.data_paths import DATA_ENV, shared_data_dir


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Mark every test that uses the ``shared_data`` fixture, so ``-m "not shared_data"`` leaves them out."""
    for item in items:
        if "shared_data" in getattr(item, "fixturenames", ()):
            item.add_marker(pytest.mark.shared_data)


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """The shared benchmark data: fails under CI when missing, skips (with the reason) elsewhere."""
    root = shared_data_dir()
    if (root / "sequences").is_dir():
        return root
    message = f"shared data not found at {root} (set {DATA_ENV} to its location)"
    if os.environ.get("CI"):
        pytest.fail(message)
    pytest.skip(message)


@pytest.fixture
def channel() -> str:
    """A python-can virtual channel of the test's own."""
    return f"gimbaltrack-test-{uuid.uuid4().hex}"


@pytest.fixture
def peer(channel: str) -> Iterator[ScriptedPeer]:
    """A scripted gimbal on ``channel``: it answers what the test tells it to."""
    bus = can.Bus(interface="virtual", channel=channel)
    with ScriptedPeer(bus) as scripted:
        yield scripted
    bus.shutdown()
