"""What the console draws over a frame: the centre and the dead zone, the detector's candidates,
the subject box in its state's colour, scaled to the shrunk view; the loop's frame stays clean."""
from __future__ import annotations

import numpy as np
import pytest

from pipelines.console.operator import ConsoleView
from pipelines.console.overlay import CANDIDATE_COLOUR, CENTRE_COLOUR, STATE_COLOURS, draw, shrunk

SOURCE = (1280, 720)


def _view(state: str = "tracking", box=(200.0, 300.0, 100.0, 80.0),
          candidates=((800.0, 100.0, 120.0, 60.0),)) -> ConsoleView:
    return ConsoleView(12, 0.0, state, box, 0.8, (3.0, -1.0), candidates)


def _has(image: np.ndarray, colour: tuple[int, int, int], x: int, y: int) -> bool:
    """``colour`` within a pixel of (x, y)."""
    patch = image[max(0, y - 1):y + 2, max(0, x - 1):x + 2].reshape(-1, 3)
    return bool((np.abs(patch.astype(int) - colour).max(axis=1) <= 2).any())


def _drawn(view: ConsoleView, width: int, dead_zone_px: float) -> tuple[np.ndarray, float, np.ndarray]:
    source = np.zeros((SOURCE[1], SOURCE[0], 3), np.uint8)
    image, scale = shrunk(source, width)
    draw(image, view, scale, dead_zone_px)
    return image, scale, source


@pytest.mark.parametrize("state", sorted(STATE_COLOURS))
def test_the_subject_box_is_drawn_in_its_state_colour_at_the_view_scale(state: str) -> None:
    image, scale, source = _drawn(_view(state), 640, 0.0)
    assert scale == 0.5 and image.shape[:2] == (360, 640)
    colour = STATE_COLOURS[state]
    # the box's corners (200, 300)-(300, 380) in source pixels, halved
    assert _has(image, colour, 100, 150) and _has(image, colour, 150, 190)
    assert _has(image, colour, 125, 150)  # its top edge
    assert not _has(image, colour, 125, 170)  # not filled
    assert not source.any()  # the loop's frame is never drawn on


def test_candidates_the_centre_and_the_dead_zone_are_drawn() -> None:
    image, _, _ = _drawn(_view(box=None), 640, 40.0)
    assert _has(image, CANDIDATE_COLOUR, 400, 50) and _has(image, CANDIDATE_COLOUR, 460, 80)
    assert _has(image, CENTRE_COLOUR, 320, 180)  # the cross at the centre
    # the dead zone: a square of half-width 40 source px = 20 view px around the centre
    assert _has(image, CENTRE_COLOUR, 300, 200) and _has(image, CENTRE_COLOUR, 340, 160)
    assert not _has(image, CENTRE_COLOUR, 290, 210)
    wider, _, _ = _drawn(_view(box=None), 640, 80.0)
    assert _has(wider, CENTRE_COLOUR, 280, 220) and not _has(image, CENTRE_COLOUR, 280, 220)


def test_no_box_is_drawn_without_an_estimate() -> None:
    image, _, _ = _drawn(_view(box=None, candidates=()), 640, 0.0)
    for colour in STATE_COLOURS.values():
        assert not (np.abs(image.astype(int) - colour).max(axis=2) <= 2).any()
    assert not (np.abs(image.astype(int) - CANDIDATE_COLOUR).max(axis=2) <= 2).any()
