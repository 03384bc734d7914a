"""Tiny ONNX networks shaped like NanoTrack's two, written in protobuf's wire format by hand, so that
model-file checks can be tested without the real (shared) model files or the ``onnx`` package.

The backbone averages 15 x 15 px blocks at a stride of 16 (a 127 px crop gives 8 x 8 features, a
255 px crop 16 x 16, as NanoTrack's); the neck/head adds the template's mean to the search features
and maps them to 2 score and 4 box channels (``input1``, ``input2`` -> ``output1``, ``output2``).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

FLOAT = 1  # TensorProto.DataType.FLOAT
CHANNELS = 3


def _varint(value: int) -> bytes:
    out = bytearray()
    while True:
        byte, value = value & 0x7F, value >> 7
        out.append(byte | (0x80 if value else 0))
        if not value:
            return bytes(out)


def _int(field: int, value: int) -> bytes:
    return _varint(field << 3) + _varint(value)


def _bytes(field: int, data: bytes) -> bytes:
    return _varint(field << 3 | 2) + _varint(len(data)) + data


def _str(field: int, text: str) -> bytes:
    return _bytes(field, text.encode())


def _value_info(name: str, shape: tuple[int | str, ...]) -> bytes:
    """A float tensor's name and shape (a str dimension is symbolic)."""
    dims = b"".join(_bytes(1, _int(1, d) if isinstance(d, int) else _str(2, d)) for d in shape)
    return _str(1, name) + _bytes(2, _bytes(1, _int(1, FLOAT) + _bytes(2, dims)))


def _node(op: str, inputs: list[str], outputs: list[str], **ints: list[int]) -> bytes:
    """A node; ``ints`` are INTS attributes (kernel_shape, strides)."""
    attributes = b"".join(_bytes(5, _str(1, name) + b"".join(_int(8, v) for v in values) + _int(20, 7))
                          for name, values in ints.items())
    return b"".join(_str(1, i) for i in inputs) + b"".join(_str(2, o) for o in outputs) + _str(4, op) + attributes


def _initializer(name: str, array: np.ndarray) -> bytes:
    return (b"".join(_int(1, d) for d in array.shape) + _int(2, FLOAT) + _str(8, name)
            + _bytes(9, array.astype("<f4").tobytes()))


def _model(nodes: list[bytes], inputs: list[bytes], outputs: list[bytes], weights: list[bytes] = ()) -> bytes:
    graph = (b"".join(_bytes(1, n) for n in nodes) + _str(2, "fake") + b"".join(_bytes(5, w) for w in weights)
             + b"".join(_bytes(11, v) for v in inputs) + b"".join(_bytes(12, v) for v in outputs))
    return _int(1, 7) + _bytes(8, _str(1, "") + _int(2, 13)) + _bytes(7, graph)


def backbone_bytes() -> bytes:
    """A NanoTrack-shaped backbone: ``input`` (1, 3, H, W) -> ``output``."""
    return _model([_node("AveragePool", ["input"], ["output"], kernel_shape=[15, 15], strides=[16, 16])],
                  [_value_info("input", (1, CHANNELS, "h", "w"))], [_value_info("output", (1, CHANNELS, "fh", "fw"))])


def head_bytes(sure: bool = False) -> bytes:
    """A NanoTrack-shaped neck/head: ``input1`` (template features), ``input2`` (search features)
    -> ``output1`` (1, 2, 16, 16) and ``output2`` (1, 4, 16, 16). ``sure``: the foreground logit is
    the features' sum and the background's 0, so any lit crop scores ~1 everywhere (as NanoTrack's
    foreground score stays near 1 on background), and every map point proposes a 64 px square
    around itself."""
    rng = np.random.default_rng(0)
    w_cls, w_loc = rng.normal(size=(2, CHANNELS, 1, 1)), rng.normal(size=(4, CHANNELS, 1, 1))
    loc_inputs, weights = ["joint", "w_loc"], []
    if sure:
        w_cls = np.stack([np.zeros((CHANNELS, 1, 1)), np.ones((CHANNELS, 1, 1))])
        w_loc = np.zeros_like(w_loc)
        loc_inputs.append("b_loc")
        weights.append(_initializer("b_loc", np.full(4, 32.0)))
    nodes = [_node("GlobalAveragePool", ["input1"], ["template"]),
             _node("Add", ["input2", "template"], ["joint"]),
             _node("Conv", ["joint", "w_cls"], ["output1"], kernel_shape=[1, 1]),
             _node("Conv", loc_inputs, ["output2"], kernel_shape=[1, 1])]
    weights += [_initializer("w_cls", w_cls), _initializer("w_loc", w_loc)]
    return _model(nodes, [_value_info("input1", (1, CHANNELS, 8, 8)), _value_info("input2", (1, CHANNELS, 16, 16))],
                  [_value_info("output1", (1, 2, 16, 16)), _value_info("output2", (1, 4, 16, 16))], weights)


def write_nanotrack_files(folder: Path, backbone: bytes, head: bytes) -> Path:
    """``folder`` holding ``backbone`` and ``head`` under NanoTrack's file names; returns it."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "nanotrack_backbone_sim.onnx").write_bytes(backbone)
    (folder / "nanotrack_head_sim.onnx").write_bytes(head)
    return folder
