"""The console's drawing over a frame: centre and dead zone, detector candidates, the subject box
coloured by state, and one status line. Drawn on the shrunk copy the viewer gets, never on the
loop's frame."""
from __future__ import annotations

import cv2
import numpy as np

from pipelines.console.operator import ConsoleView

STATE_COLOURS = {  # BGR, as the annotated video's
    "tracking": (0, 200, 0),
    "searching": (0, 200, 255),
    "lost": (0, 0, 255),
    "paused": (255, 160, 0),
}
CANDIDATE_COLOUR = (255, 0, 255)
CENTRE_COLOUR = (200, 200, 200)
_FONT = cv2.FONT_HERSHEY_SIMPLEX


def shrunk(image: np.ndarray, max_width: int) -> tuple[np.ndarray, float]:
    """A copy at most ``max_width`` wide, and its pixels per source pixel. Bilinear: a live view
    can afford its slight aliasing, not INTER_AREA's cost at uneven ratios (more than the JPEG
    encoding itself, docs/console.md)."""
    height, width = image.shape[:2]
    if width <= max_width:
        return image.copy(), 1.0
    scale = max_width / width
    size = (max_width, max(1, round(height * scale)))
    return cv2.resize(image, size, interpolation=cv2.INTER_LINEAR), scale


def _box(image: np.ndarray, box: tuple[float, ...], scale: float, colour: tuple[int, int, int],
         thickness: int) -> None:
    x, y, w, h = (round(v * scale) for v in box)
    cv2.rectangle(image, (x, y), (x + w, y + h), colour, thickness)


def draw(image: np.ndarray, view: ConsoleView, scale: float, dead_zone_px: float) -> None:
    """Draw ``view`` on ``image`` (shrunk by ``scale`` from the source frame) in place."""
    height, width = image.shape[:2]
    centre = (width // 2, height // 2)
    cv2.drawMarker(image, centre, CENTRE_COLOUR, cv2.MARKER_CROSS, 20, 1)
    zone = max(2, round(dead_zone_px * scale))
    cv2.rectangle(image, (centre[0] - zone, centre[1] - zone), (centre[0] + zone, centre[1] + zone),
                  CENTRE_COLOUR, 1)
    for candidate in view.candidates:
        _box(image, candidate, scale, CANDIDATE_COLOUR, 1)
    if view.box is not None:
        _box(image, view.box, scale, STATE_COLOURS.get(view.state, CENTRE_COLOUR), 2)
    confidence = "" if view.confidence is None else f" conf {view.confidence:.2f}"
    text = (f"#{view.frame_index} {view.state}{confidence} "
            f"yaw {view.rates_dps[0]:+.1f} pitch {view.rates_dps[1]:+.1f} deg/s")
    size = min(0.5, max(0.3, width / 1300))  # the line fits a phone's narrow view too
    (w, h), base = cv2.getTextSize(text, _FONT, size, 1)
    cv2.rectangle(image, (4, 4), (12 + w, 10 + h + base), (0, 0, 0), cv2.FILLED)
    cv2.putText(image, text, (8, 8 + h), _FONT, size, (255, 255, 255), 1, cv2.LINE_8)
