"""NanoTrack v3 fused with VitTrack (``nanovit``), on tiny generated networks (tests/fake_onnx.py):
both follow a white square on black; the fake VitTrack here proposes boxes twice the size it searched
at, so a fused box is told from either model's own by its size."""
import numpy as np
import pytest

from tests import fake_onnx
from tracker.backends.fused import FusedBackend, FusionParams
from tracker.backends.nanotrack import V3_PARAMS, NanoTrackBackend, OrtNanoNetworks
from tracker.backends.vittrack import VitTrackBackend
from tracker.runtime.boxes import center

SIDE = 32


@pytest.fixture(scope="module")
def models(tmp_path_factory):
    return fake_onnx.onnx_model_files(tmp_path_factory.mktemp("models"))


@pytest.fixture(scope="module")
def wide_vit(tmp_path_factory):
    """A model folder whose VitTrack proposes boxes twice the subject's size."""
    folder = fake_onnx.onnx_model_files(tmp_path_factory.mktemp("wide"))
    (folder / "vittrack/vitTracker.onnx").write_bytes(fake_onnx.vittrack_bytes(size=0.5))
    return folder


def _frame(x: float, y: float, side: int = SIDE) -> np.ndarray:
    frame = np.zeros((360, 480, 3), np.uint8)
    if x >= 0:
        frame[int(y):int(y) + side, int(x):int(x) + side] = 255
    return frame


def _nano(models) -> NanoTrackBackend:
    return NanoTrackBackend(models, V3_PARAMS, OrtNanoNetworks(models), "nanotrack3")


def _fused(models, **params) -> FusedBackend:
    return FusedBackend(_nano(models), VitTrackBackend(models), FusionParams(**params))


def test_the_box_is_the_weighted_mean_of_both_models_where_vittrack_is_sure(wide_vit):
    fused, alone = _fused(wide_vit, vit_weight=0.5), _nano(wide_vit)
    start = (200.0, 150.0, SIDE, SIDE)
    fused.init(_frame(200, 150), start)
    alone.init(_frame(200, 150), start)
    for x in (204, 208, 212):
        box, _ = fused.update(_frame(x, 150))
        own, _ = alone.update(_frame(x, 150))
    # VitTrack searched at NanoTrack's box and proposed one twice its size, about the same centre
    assert box[2] == pytest.approx(1.5 * own[2], rel=0.1) and box[3] == pytest.approx(1.5 * own[3], rel=0.1)
    assert abs(center(box)[0] - center(own)[0]) <= 4 and abs(center(box)[1] - center(own)[1]) <= 4


def test_vit_weight_sets_how_far_the_box_moves_towards_vittracks(wide_vit):
    widths = []
    for weight in (0.25, 0.75):
        fused = _fused(wide_vit, vit_weight=weight)
        fused.init(_frame(200, 150), (200.0, 150.0, SIDE, SIDE))
        widths.append(fused.update(_frame(204, 150))[0][2])
    assert widths[1] > 1.3 * widths[0]


def test_nanotracks_box_stands_where_vittrack_is_unsure(wide_vit):
    fused, alone = _fused(wide_vit), _nano(wide_vit)
    for backend in (fused, alone):
        backend.init(_frame(200, 150), (200.0, 150.0, SIDE, SIDE))
        backend.update(_frame(204, 150))
    box, score = fused.update(_frame(-1, -1))  # gone: VitTrack's confidence falls under fuse_above
    own, own_score = alone.update(_frame(-1, -1))
    assert box == pytest.approx(own) and score == pytest.approx(own_score)


def test_the_anchor_likeness_is_nanotracks_so_the_verification_holds_for_nanovit(wide_vit):
    """The subject tracker verifies a box by the backend's ``anchor_likeness``; a fused backend
    without one would pass every box, cover or background included."""
    fused, alone = _fused(wide_vit), _nano(wide_vit)
    start = (200.0, 150.0, SIDE, SIDE)
    fused.init(_frame(200, 150), start)
    alone.init(_frame(200, 150), start)
    for x in (204, 208, -1, -1):
        fused.update(_frame(x, 150))
        alone.update(_frame(x, 150))
        assert fused.anchor_likeness() == pytest.approx(alone.anchor_likeness())
    assert fused.anchor_likeness() < 1.0


def test_the_second_opinion_is_vittracks_confidence_at_nanotracks_box(wide_vit, monkeypatch):
    """``second_opinion`` vouches for a box NanoTrack's own checks doubt, so it must be VitTrack's
    confidence on this frame: high on the subject, low once it has gone."""
    fused = _fused(wide_vit)
    fused.init(_frame(200, 150), (200.0, 150.0, SIDE, SIDE))
    said = []
    checker_update = fused._checker.update
    monkeypatch.setattr(fused._checker, "update", lambda frame: said.append(checker_update(frame)) or said[-1])
    opinions = []
    for x in (204, -1):
        fused.update(_frame(x, 150))
        opinions.append(fused.second_opinion())
    assert opinions == [confidence if box is not None else 0.0 for box, confidence in said]
    assert opinions[0] > 0.5 > opinions[1]
