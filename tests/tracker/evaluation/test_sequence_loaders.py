"""OTB and VOT ground truth, frame folders and video files."""
from pathlib import Path

import cv2
import numpy as np
import pytest

from tracker.evaluation.datasets import FrameReadError, list_images, load_sequence, parse_groundtruth


def _write_frames(folder: Path, count: int, name: str = "{:04d}.jpg") -> None:
    folder.mkdir(parents=True, exist_ok=True)
    for i in range(count):
        cv2.imwrite(str(folder / name.format(i + 1)), np.full((24, 32, 3), i * 20, np.uint8))


def test_otb_tab_and_comma_separated(tmp_path):
    (tmp_path / "tab.txt").write_text("1\t2\t3\t4\n5\t6\t7\t8\n")
    (tmp_path / "comma.txt").write_text("1,2,3,4\n5,6,7,8\n")
    assert parse_groundtruth(tmp_path / "tab.txt") == ((1, 2, 3, 4), (5, 6, 7, 8))
    assert parse_groundtruth(tmp_path / "comma.txt") == ((1, 2, 3, 4), (5, 6, 7, 8))


def test_vot_polygon_becomes_axis_aligned_box(tmp_path):
    (tmp_path / "gt.txt").write_text("334.0,128.0,438.0,188.0,396.0,260.0,292.0,200.0\n")
    assert parse_groundtruth(tmp_path / "gt.txt") == ((292.0, 128.0, 146.0, 132.0),)


def test_wrong_value_count_names_the_line(tmp_path):
    (tmp_path / "gt.txt").write_text("1,2,3,4\n1,2,3\n")
    with pytest.raises(ValueError, match=r"gt.txt:2"):
        parse_groundtruth(tmp_path / "gt.txt")


def test_a_utf8_byte_order_mark_is_ignored(tmp_path):
    (tmp_path / "gt.txt").write_text("\ufeff1,2,3,4\n5,6,7,8\n", encoding="utf-8")  # Windows Notepad
    assert parse_groundtruth(tmp_path / "gt.txt") == ((1, 2, 3, 4), (5, 6, 7, 8))


def test_a_blank_line_before_the_last_box_is_an_error_naming_it(tmp_path):
    """Skipped, it would pair every later box with the frame before its own."""
    (tmp_path / "gt.txt").write_text("1,2,3,4\n\n5,6,7,8\n")
    with pytest.raises(ValueError, match=r"gt.txt:2: blank line"):
        parse_groundtruth(tmp_path / "gt.txt")
    (tmp_path / "end.txt").write_text("1,2,3,4\r\n5,6,7,8\r\n\r\n \n")  # blank lines at the end are fine
    assert parse_groundtruth(tmp_path / "end.txt") == ((1, 2, 3, 4), (5, 6, 7, 8))


def test_nan_lines_are_frames_without_the_subject(tmp_path):
    (tmp_path / "gt.txt").write_text("1,2,3,4\nNaN,NaN,NaN,NaN\n0,0,0,0\n")
    boxes = parse_groundtruth(tmp_path / "gt.txt")
    assert len(boxes) == 3 and all(np.isnan(boxes[1])) and boxes[2] == (0, 0, 0, 0)


def test_otb_folder(tmp_path):
    _write_frames(tmp_path / "seq" / "img", 3)
    (tmp_path / "seq" / "groundtruth_rect.txt").write_text("1\t2\t3\t4\n" * 3)
    seq = load_sequence(tmp_path / "seq")
    assert (seq.name, len(seq)) == ("seq", 3)
    frames = list(seq.frames())
    assert len(frames) == 3 and frames[2][0, 0, 0] == 40


@pytest.mark.parametrize("subdir", ["imgs", ""])
def test_vot_folder_with_frames_in_imgs_or_directly(tmp_path, subdir):
    _write_frames(tmp_path / "vot" / subdir if subdir else tmp_path / "vot", 2, "{:08d}.jpg")
    (tmp_path / "vot" / "groundtruth.txt").write_text("0,0,10,0,10,5,0,5\n" * 2)
    seq = load_sequence(tmp_path / "vot")
    assert seq.groundtruth == ((0, 0, 10, 5), (0, 0, 10, 5))
    assert len(list(seq.frames())) == 2


def test_image_folder_without_groundtruth(tmp_path):
    _write_frames(tmp_path, 4)
    seq = load_sequence(tmp_path)
    assert seq.groundtruth is None and len(seq) == 4


def test_unpadded_frames_are_read_in_natural_order(tmp_path):
    _write_frames(tmp_path / "img", 11, "{}.jpg")
    (tmp_path / "img" / "notes.txt").write_text("not an image")
    (tmp_path / "img" / "12.PNG").write_bytes((tmp_path / "img" / "1.jpg").read_bytes())
    assert [p.name for p in list_images(tmp_path / "img")] == [f"{i}.jpg" for i in range(1, 12)] + ["12.PNG"]
    seq = load_sequence(tmp_path)
    assert [p.name for p in seq.frame_paths[:3]] == ["1.jpg", "2.jpg", "3.jpg"]
    assert [int(f[0, 0, 0]) for f in list(seq.frames())[:3]] == [0, 20, 40]


def test_more_boxes_than_frames_is_an_error(tmp_path):
    _write_frames(tmp_path / "img", 2)
    (tmp_path / "groundtruth_rect.txt").write_text("1,2,3,4\n" * 3)
    with pytest.raises(ValueError, match="only 2 frames"):
        load_sequence(tmp_path)


def test_fewer_boxes_than_frames_is_an_error(tmp_path):
    """Not scored against frames 1..n: an annotation may start at a later frame (OTB-2015's David)."""
    _write_frames(tmp_path / "img", 3)
    (tmp_path / "groundtruth_rect.txt").write_text("1,2,3,4\n" * 2)
    with pytest.raises(ValueError, match="2 boxes but .* has 3 frames: one box per frame"):
        load_sequence(tmp_path)
    (tmp_path / "video").mkdir()
    _write_video(tmp_path / "video" / "clip.avi", 5)
    (tmp_path / "video" / "clip.txt").write_text("1,2,3,4\n" * 4)
    with pytest.raises(ValueError, match="4 boxes but .*clip.avi has 5 frames"):
        load_sequence(tmp_path / "video" / "clip.avi")


def test_an_unreadable_frame_names_the_sequence_and_the_frame(tmp_path):
    _write_frames(tmp_path / "seq" / "img", 3)
    (tmp_path / "seq" / "img" / "0002.jpg").write_bytes(b"not a jpeg")
    (tmp_path / "seq" / "groundtruth_rect.txt").write_text("1,2,3,4\n" * 3)
    frames = load_sequence(tmp_path / "seq").frames()
    assert next(frames).shape == (24, 32, 3)
    with pytest.raises(FrameReadError, match=r"seq: cannot read frame 2 \(.*0002.jpg\)"):
        next(frames)


def test_a_video_ending_early_names_the_sequence_and_the_frame(tmp_path):
    _write_video(tmp_path / "full.avi", 30)
    data = (tmp_path / "full.avi").read_bytes()
    (tmp_path / "clip.avi").write_bytes(data[:len(data) // 2])  # its header still says 30 frames
    (tmp_path / "clip.txt").write_text("1,2,3,4\n" * 30)
    frames = load_sequence(tmp_path / "clip.avi").frames()
    with pytest.raises(FrameReadError, match=r"clip: cannot read frame \d+ of the 30 in .*clip.avi"):
        list(frames)  # once: fewer frames, silently


def _write_video(path: Path, count: int) -> None:
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), 25, (32, 24))
    for i in range(count):
        writer.write(np.full((24, 32, 3), i * 30 % 256, np.uint8))
    writer.release()


@pytest.mark.parametrize("name", ["clip.txt", "clip_groundtruth.txt"])
def test_video_with_groundtruth_beside_it(tmp_path, name):
    _write_video(tmp_path / "clip.avi", 5)
    (tmp_path / name).write_text("1,2,3,4\n" * 5)
    seq = load_sequence(tmp_path / "clip.avi")
    assert len(seq) == 5 and len(list(seq.frames())) == 5


def test_video_with_given_groundtruth(tmp_path):
    _write_video(tmp_path / "clip.avi", 3)
    (tmp_path / "boxes.txt").write_text("0,0,4,0,4,4,0,4\n" * 3)
    seq = load_sequence(tmp_path / "clip.avi", tmp_path / "boxes.txt")
    assert seq.groundtruth[0] == (0, 0, 4, 4)


def test_missing_path_and_empty_folder(tmp_path):
    with pytest.raises(FileNotFoundError, match="no such sequence"):
        load_sequence(tmp_path / "nope")
    with pytest.raises(ValueError, match="no image frames"):
        load_sequence(tmp_path)


def test_shared_sequences_load(shared_data):
    for name in ("otb_crossing", "otb_surfer", "vot_bag", "vot15_ball1"):
        seq = load_sequence(shared_data / "sequences" / name)
        first = next(seq.frames())
        assert first.ndim == 3 and len(seq) == len(seq.groundtruth) > 100
    video = load_sequence(shared_data / "clips/clip_vot_bag_video/bag.avi",
                          shared_data / "sequences/vot_bag/groundtruth.txt")
    assert len(video) == 196


# A ground-truth file without a single box.
@pytest.mark.parametrize("text", ["", "\n", " \r\n\n"], ids=["empty", "one-blank-line", "blank-lines-crlf"])
def test_a_file_without_boxes_is_an_error(tmp_path: Path, text: str) -> None:
    """An empty annotation would otherwise make a sequence of no frames."""
    (tmp_path / "gt.txt").write_text(text)
    with pytest.raises(ValueError, match="gt.txt: no ground-truth boxes"):
        parse_groundtruth(tmp_path / "gt.txt")


# Ground truth written with spaces between the values.
def test_space_separated_boxes_and_polygons(tmp_path: Path) -> None:
    (tmp_path / "gt.txt").write_text("1 2 3 4\n5  6 7 8\n1 1 5 1 5 4 1 4\n")
    assert parse_groundtruth(tmp_path / "gt.txt") == ((1, 2, 3, 4), (5, 6, 7, 8), (1, 1, 4, 3))
