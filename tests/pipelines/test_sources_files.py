"""Video files and image folders: frames, metadata, timestamps, pacing and errors."""
from __future__ import annotations

import threading
from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np
import pytest

from pipelines.sources import FrameSource, SourceError, open_source
from pipelines.sources.files import ASSUMED_FPS, Pacer


class FakeClock:
    """A clock that only moves when told to or when ``sleep`` is called."""

    def __init__(self, start: float = 100.0) -> None:
        self.now = start
        self.sleeps: list[float] = []

    def __call__(self) -> float:
        return self.now

    def sleep(self, seconds: float) -> None:
        self.sleeps.append(seconds)
        self.now += seconds


def brightness(image: np.ndarray) -> float:
    return float(np.median(image))


def test_video_file_frames_metadata_and_timestamps(small_video: Path) -> None:
    with open_source(str(small_video)) as source:
        assert (source.size, source.fps, source.frame_count) == ((96, 64), 25.0, 12)
        assert not source.is_live and source.dropped == 0
        frames = list(source)
    assert [f.index for f in frames] == list(range(12))
    assert [f.timestamp for f in frames] == pytest.approx([i / 25 for i in range(12)])
    assert [brightness(f.image) for f in frames] == pytest.approx([20 + 10 * i for i in range(12)], abs=5)


def test_fps_argument_overrides_the_file_rate(small_video: Path) -> None:
    with open_source(str(small_video), fps=10.0) as source:
        assert source.fps == 10.0
        assert [f.timestamp for f in source][-1] == pytest.approx(1.1)


def test_closed_source_yields_nothing(small_video: Path) -> None:
    source = open_source(str(small_video))
    assert source.read() is not None
    source.close()
    source.close()
    assert source.read() is None and list(source) == []


def test_realtime_file_waits_for_each_frame_and_stamps_with_the_clock(small_video: Path) -> None:
    clock = FakeClock()
    with open_source(str(small_video), realtime=True, clock=clock, sleep=clock.sleep) as source:
        stamps = []
        for frame in source:
            stamps.append(frame.timestamp)
            clock.now += 0.01  # the consumer works 10 ms per frame, faster than 25 fps
    assert stamps == pytest.approx([100.0 + i / 25 for i in range(12)])
    assert clock.sleeps == pytest.approx([0.03] * 11)


def test_pacer_never_sleeps_for_a_late_consumer_and_skips_nothing() -> None:
    clock = FakeClock(0.0)
    pacer = Pacer(10.0, realtime=True, clock=clock, sleep=clock.sleep)
    stamps = []
    for index in range(4):
        stamps.append(pacer.stamp(index))
        clock.now += 0.25  # slower than 10 fps
    assert stamps == pytest.approx([0.0, 0.25, 0.5, 0.75])
    assert clock.sleeps == []


def test_pacer_without_realtime_uses_index_over_fps_and_never_sleeps() -> None:
    clock = FakeClock()
    pacer = Pacer(30.0, realtime=False, clock=clock, sleep=clock.sleep)
    assert [pacer.stamp(i) for i in (0, 3, 30)] == pytest.approx([0.0, 0.1, 1.0])
    assert clock.sleeps == []
    with pytest.raises(ValueError):
        Pacer(0.0, realtime=False)


def test_image_folder_in_natural_order(tmp_path: Path, frame_image) -> None:
    for index, name in enumerate(["img1.png", "img2.jpg", "img10.png"]):
        cv2.imwrite(str(tmp_path / name), frame_image(index))
    (tmp_path / "notes.txt").write_text("not an image")
    with open_source(str(tmp_path)) as source:
        assert (source.size, source.fps, source.frame_count) == ((96, 64), None, 3)
        frames = list(source)
    assert [brightness(f.image) for f in frames] == pytest.approx([20, 30, 40], abs=3)
    assert [f.timestamp for f in frames] == pytest.approx([0, 1 / ASSUMED_FPS, 2 / ASSUMED_FPS])


def test_image_folder_reads_only_jpg_and_png_files(tmp_path: Path, frame_image) -> None:
    """Other image types tracker.evaluation.datasets lists (.bmp, .tif, .webp) and folders are left out."""
    cv2.imwrite(str(tmp_path / "1.jpeg"), frame_image(0))
    cv2.imwrite(str(tmp_path / "2.bmp"), frame_image(1))
    cv2.imwrite(str(tmp_path / "3.tif"), frame_image(2))
    (tmp_path / "4.png").mkdir()
    cv2.imwrite(str(tmp_path / "10.PNG"), frame_image(3))
    with open_source(str(tmp_path)) as source:
        assert source.frame_count == 2
        frames = list(source)
    assert [brightness(f.image) for f in frames] == pytest.approx([20, 50], abs=3)


def test_missing_path(tmp_path: Path) -> None:
    with pytest.raises(SourceError, match="no such video file or image folder"):
        open_source(str(tmp_path / "nope.mp4"))


def test_garbage_file_named_mp4(tmp_path: Path) -> None:
    fake = tmp_path / "fake.mp4"
    fake.write_bytes(np.random.default_rng(1).integers(0, 256, 4096, dtype=np.uint8).tobytes())
    with pytest.raises(SourceError, match=r"cannot open|no frame decodes") as error:
        open_source(str(fake))
    assert "\n" not in str(error.value)


def test_empty_folder(tmp_path: Path) -> None:
    with pytest.raises(SourceError, match="no .jpg or .png images"):
        open_source(str(tmp_path))


def test_unreadable_image_in_folder(tmp_path: Path) -> None:
    (tmp_path / "0001.jpg").write_bytes(b"not a jpeg")
    with pytest.raises(SourceError, match="cannot read image"):
        open_source(str(tmp_path))


def test_an_image_of_another_size_in_the_folder_is_a_source_error(tmp_path: Path, frame_image) -> None:
    for i, size in enumerate([(96, 64), (96, 64), (80, 64)]):
        cv2.imwrite(str(tmp_path / f"{i:04d}.png"), frame_image(i, size))
    with open_source(str(tmp_path)) as source:
        assert source.read() is not None and source.read() is not None
        with pytest.raises(SourceError, match="0002.png is 80x64, the folder's first is 96x64"):
            source.read()


def test_decoding_ahead_keeps_order_and_stops_on_close(small_video: Path) -> None:
    source = open_source(str(small_video))
    first = [source.read() for _ in range(3)]
    assert [f.index for f in first] == [0, 1, 2]
    decoder = source._decoder
    assert decoder.is_alive()  # frames are waiting in the queue for the consumer
    source.close()
    assert not decoder.is_alive()
    assert source.read() is None


def test_a_benchmark_sequence_folder_is_read_from_its_frames_subfolder(tmp_path: Path, frame_image) -> None:
    (tmp_path / "img").mkdir()
    for i in range(3):
        cv2.imwrite(str(tmp_path / "img" / f"{i + 1:04d}.jpg"), frame_image(i))
    (tmp_path / "groundtruth_rect.txt").write_text("1,2,3,4\n")
    with open_source(str(tmp_path)) as source:
        assert source.frame_count == 3 and len(list(source)) == 3


# A file source read again after its end or after a decode error returns ``None`` at once, never
# waits for a decoder thread that has already finished.
def _read_again(source: FrameSource) -> list[object]:
    """``source.read()`` on a helper thread: what it returned, or nothing if it is still waiting."""
    result: list[object] = []
    reader = threading.Thread(target=lambda: result.append(source.read()), daemon=True)
    reader.start()
    reader.join(5.0)
    return result


def test_a_read_after_the_end_is_none(small_video: Path) -> None:
    with open_source(str(small_video)) as source:
        assert len(list(source)) == 12
        assert _read_again(source) == [None]


def test_a_read_after_a_decode_error_is_none(tmp_path: Path, frame_image: Callable[..., object]) -> None:
    for i, size in enumerate([(96, 64), (80, 64), (96, 64)]):
        cv2.imwrite(str(tmp_path / f"{i:04d}.png"), frame_image(i, size))
    with open_source(str(tmp_path)) as source:
        assert source.read() is not None
        with pytest.raises(SourceError, match="0001.png is 80x64"):
            source.read()
        assert _read_again(source) == [None]


# ``open_source`` takes a path object and an int camera index as well as strings (both were an
# AttributeError on ``.strip``), and names any other type in a SourceError.
def test_a_path_object_opens_like_its_string(small_video: Path) -> None:
    with open_source(small_video) as by_path, open_source(str(small_video)) as by_text:
        assert [f.index for f in by_path] == [f.index for f in by_text]


def test_a_missing_path_object_is_named(tmp_path: Path) -> None:
    with pytest.raises(SourceError, match="no such video file or image folder"):
        open_source(tmp_path / "missing.mp4")


def test_an_int_index_is_a_camera() -> None:
    with pytest.raises(SourceError, match="camera 97 does not open"):
        open_source(97)


@pytest.mark.parametrize("spec", [None, 1.5, True, b"clip.mp4"])
def test_other_types_are_named(spec: object) -> None:
    with pytest.raises(SourceError, match="a source is a path, camera index or stream URL, not"):
        open_source(spec)  # type: ignore[arg-type]
