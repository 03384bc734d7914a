"""The camera's own motion between two grey images: how the background moved, for the motion detector.

Corners of the older image are followed into the newer one by pyramidal optical flow, and a
similarity transform (shift, rotation, zoom) is fitted to them by RANSAC, so a subject moving
across part of the picture does not pull the fit; the corners that agree must be spread over the
picture (``MIN_CELLS``), or a moving thing on a flat background would be taken for the camera.
"""
from __future__ import annotations

import cv2
import numpy as np

FIT_SIDE = 400  # images longer than this (and 2 px high and wide) are halved for the fit (a third of its cost)
MAX_CORNERS = 100
MIN_INLIERS = 20  # fewer corners agreeing on one motion: the camera's motion cannot be told
MIN_INLIER_SHARE = 0.3  # ... or fewer than this share of the corners followed
GRID = 4  # the picture in GRID x GRID cells: the agreeing corners must lie in MIN_CELLS of them,
MIN_CELLS = 8  # so that a thing moving over part of the picture is not taken for the camera
STILL_PX = 0.5  # a motion that moves no corner of the image further than this: the camera stood still
RANSAC_PX = 1.0  # in the given images' pixels


def camera_motion(older: np.ndarray, newer: np.ndarray) -> np.ndarray | None:
    """The 2 x 3 transform that carries ``older``'s pixels to where they are in ``newer`` (same size,
    ``uint8`` grey), or None when the camera stood still or its motion cannot be told (too few
    corners, or too few of them agreeing)."""
    shape = older.shape
    factor = 2.0 if max(shape) > FIT_SIDE and min(shape[:2]) >= 2 else 1.0  # a 1 px side cannot be halved
    if factor > 1.0:
        older, newer = (cv2.resize(i, None, fx=0.5, fy=0.5, interpolation=cv2.INTER_AREA) for i in (older, newer))
    corners = cv2.goodFeaturesToTrack(older, MAX_CORNERS, 0.01, max(4, max(older.shape) // 40), blockSize=5)
    if corners is None or len(corners) < MIN_INLIERS:
        return None
    moved, status, _ = cv2.calcOpticalFlowPyrLK(older, newer, corners, None, winSize=(21, 21), maxLevel=3)
    followed = status.ravel() == 1
    if followed.sum() < MIN_INLIERS:
        return None
    matrix, inliers = cv2.estimateAffinePartial2D(corners[followed], moved[followed], method=cv2.RANSAC,
                                                  ransacReprojThreshold=RANSAC_PX / factor)
    if matrix is None:
        return None
    agreeing = inliers.ravel() == 1
    if agreeing.sum() < max(MIN_INLIERS, MIN_INLIER_SHARE * len(corners)):
        return None
    if _cells(corners[followed][agreeing], older.shape) < MIN_CELLS:
        return None
    matrix[:, 2] *= factor
    return None if _largest_shift(matrix, shape) <= STILL_PX else matrix


def warp(image: np.ndarray, matrix: np.ndarray, nearest: bool = False) -> np.ndarray:
    """``image`` carried by ``matrix`` into the newer image's pixels; uncovered pixels copy the edge."""
    flags = cv2.INTER_NEAREST if nearest else cv2.INTER_LINEAR
    return cv2.warpAffine(image, matrix, image.shape[1::-1], flags=flags, borderMode=cv2.BORDER_REPLICATE)


def covered(shape: tuple[int, ...], matrix: np.ndarray) -> np.ndarray:
    """The pixels of the newer image that the older one (of ``shape``) saw, less a pixel's margin
    (0 or 255)."""
    seen = cv2.warpAffine(np.full(shape[:2], 255, np.uint8), matrix, shape[1::-1], flags=cv2.INTER_NEAREST,
                          borderMode=cv2.BORDER_CONSTANT, borderValue=0)
    return cv2.erode(seen, np.ones((3, 3), np.uint8), borderType=cv2.BORDER_CONSTANT, borderValue=0)


def _cells(points: np.ndarray, shape: tuple[int, ...]) -> int:
    """In how many of the ``GRID`` x ``GRID`` cells of an image of ``shape`` ``points`` (N x 1 x 2) lie."""
    height, width = shape[:2]
    xy = points.reshape(-1, 2)
    column = np.clip((xy[:, 0] * GRID / width).astype(int), 0, GRID - 1)
    row = np.clip((xy[:, 1] * GRID / height).astype(int), 0, GRID - 1)
    return len(np.unique(row * GRID + column))


def _largest_shift(matrix: np.ndarray, shape: tuple[int, ...]) -> float:
    """How far ``matrix`` moves the farthest-moved corner of an image of ``shape``."""
    height, width = shape[:2]
    corners = np.array([[0, 0, 1], [width - 1, 0, 1], [0, height - 1, 1], [width - 1, height - 1, 1]], float)
    return float(np.abs(corners @ matrix.T - corners[:, :2]).max())
