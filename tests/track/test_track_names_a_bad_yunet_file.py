"""A ``face_detection_yunet*.onnx`` in ``--model-dir`` that is damaged, or another network under
YuNet's name, is a one-line error naming the file, exit 2, before ``--out`` is created (it was a
cv2.error traceback: at the start for a damaged file, at the first frame, mid-run, for another
network)."""
from __future__ import annotations

from pathlib import Path

import pytest

from tests import fake_onnx
from tests.track.helpers import drifting, make_clip, run_track


@pytest.mark.parametrize("content", [b"not a network", fake_onnx.head_bytes(), fake_onnx.backbone_bytes()],
                         ids=["damaged", "nanotrack-head", "nanotrack-backbone"])
def test_a_bad_yunet_file_is_a_one_line_error(content: bytes, tmp_path: Path,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    models = tmp_path / "models"
    models.mkdir()
    model = models / "face_detection_yunet_2023mar.onnx"
    model.write_bytes(content)
    out = tmp_path / "out"
    assert run_track(make_clip(tmp_path / "clip.avi", 5, drifting), out, "--detect", "face",
                     "--model-dir", str(models), "--no-video") == 2
    err = capsys.readouterr().err
    assert err == (f"gimbaltrack track: error: YuNet face detector {model}: not a YuNet network "
                   "(damaged or another file?)\n")
    assert not out.exists()
