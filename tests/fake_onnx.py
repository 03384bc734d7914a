"""Tiny ONNX networks shaped like the trackers' models (NanoTrack v2 and v3, VitTrack, FEAR-XS),
written in protobuf's wire format by hand, so that model-file checks and the backends' decoding can
be tested without the real (shared) model files or the ``onnx`` package.

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


def _channel_mix(name: str, source: str, out: str, weights: np.ndarray, bias: np.ndarray) -> tuple[bytes, list[bytes]]:
    """A 1 x 1 convolution of ``source`` into ``out`` with (out, in) ``weights`` and ``bias``."""
    w = weights.reshape(*weights.shape, 1, 1)
    node = _node("Conv", [source, f"{name}_w", f"{name}_b"], [out], kernel_shape=[1, 1])
    return node, [_initializer(f"{name}_w", w), _initializer(f"{name}_b", bias)]


def _smooth_pool(source: str, kernel: int, before: int, after: int) -> bytes:
    """Means over ``kernel`` px windows 16 px apart (the first starting ``before`` px before the
    crop), so that a bright square of about ``kernel`` px peaks where it lies, rather than tying
    with every cell it covers."""
    return _node("AveragePool", [source], ["pooled"], kernel_shape=[kernel, kernel], strides=[16, 16],
                 pads=[before, before, after, after])


def vittrack_bytes(size: float = 0.25, offset: float = 1.0) -> bytes:
    """A VitTrack-shaped network (``template`` 128 px, ``search`` 256 px -> ``output1`` 1x1x16x16,
    ``output2`` and ``output3`` 1x2x16x16): its confidence is the sigmoid of twice the mean normalised
    value around each 16 px block of the search crop (``_smooth_pool``), so it peaks on bright cells (a white subject on
    black: ~0.99 against ~0.01); every cell proposes a box ``size`` of the crop wide and high, at
    ``offset`` of a cell from its upper-left corner (1.0: its lower-right corner, where the window
    whose mean it takes is centred)."""
    conf, w1 = _channel_mix("conf", "pooled", "output1", np.full((1, CHANNELS), 2.0 / CHANNELS), np.zeros(1))
    sizes, w2 = _channel_mix("size", "pooled", "output2", np.zeros((2, CHANNELS)), np.full(2, size))
    offsets, w3 = _channel_mix("offset", "pooled", "output3", np.zeros((2, CHANNELS)), np.full(2, offset))
    nodes = [_smooth_pool("search", 64, 16, 32),  # window k centred on block k's lower-right corner
             _node("Conv", ["pooled", "conf_w", "conf_b"], ["logit"], kernel_shape=[1, 1]),
             _node("Sigmoid", ["logit"], ["output1"]), sizes, offsets]
    return _model(nodes, [_value_info("template", (1, CHANNELS, 128, 128)), _value_info("search", (1, CHANNELS, 256, 256))],
                  [_value_info("output1", (1, 1, 16, 16)), _value_info("output2", (1, 2, 16, 16)),
                   _value_info("output3", (1, 2, 16, 16))], [*w1, *w2, *w3])


def fear_template_bytes() -> bytes:
    """A FEAR-XS-shaped template network: ``image`` 1x3x128x128 -> ``features`` 1x256x8x8, the mean
    colour of each 16 px block, channel by channel, repeated."""
    mix = np.tile(np.eye(CHANNELS), (256 // CHANNELS + 1, 1))[:256]
    node, weights = _channel_mix("feat", "pooled", "features", mix, np.zeros(256))
    nodes = [_node("AveragePool", ["image"], ["pooled"], kernel_shape=[16, 16], strides=[16, 16]), node]
    return _model(nodes, [_value_info("image", (1, CHANNELS, 128, 128))], [_value_info("features", (1, 256, 8, 8))],
                  weights)


def fear_search_bytes(side: float = 25.6) -> bytes:
    """A FEAR-XS-shaped search network: ``image`` 1x3x256x256 and ``template_features`` ->
    ``cls`` 1x1x16x16 logits, ``(mean around a 16 px block / 255 - 0.5) x 10`` (a white cell +5, a black
    one -5), and ``bbox`` 1x4x16x16, ``side`` px to each side of every grid point (25.6: the box's own
    size, as the search crop is 5 boxes wide resized to 256 px)."""
    cls, w1 = _channel_mix("cls", "pooled", "cls", np.full((1, CHANNELS), 10.0 / 255 / CHANNELS), np.full(1, -5.0))
    box, w2 = _channel_mix("box", "pooled", "bbox", np.zeros((4, CHANNELS)), np.full(4, side))
    nodes = [_smooth_pool("image", 48, 24, 8), cls, box]  # window k centred on grid point 16 k
    return _model(nodes, [_value_info("image", (1, CHANNELS, 256, 256)), _value_info("template_features", (1, 256, 8, 8))],
                  [_value_info("bbox", (1, 4, 16, 16)), _value_info("cls", (1, 1, 16, 16))], [*w1, *w2])


def nanotrack_v3_backbone_bytes() -> bytes:
    """A NanoTrack-v3-shaped backbone: ``input`` 1x3x255x255 -> ``output`` 1x96x16x16 (a 127 px crop
    gives 8 x 8), the mean brightness of 15 px blocks at a stride of 16 in all 96 channels."""
    node, weights = _channel_mix("feat", "pooled", "output", np.full((96, CHANNELS), 1.0 / CHANNELS), np.zeros(96))
    nodes = [_node("AveragePool", ["input"], ["pooled"], kernel_shape=[15, 15], strides=[16, 16]), node]
    return _model(nodes, [_value_info("input", (1, CHANNELS, 255, 255))], [_value_info("output", (1, 96, 16, 16))],
                  weights)


def nanotrack_v3_head_bytes(side: float = 32.0) -> bytes:
    """A NanoTrack-v3-shaped neck/head: ``input1`` 1x96x8x8 and ``input2`` 1x96x16x16 -> ``output1``
    1x2x15x15 (background logit 0, foreground ``(brightness / 255 - 0.5) x 10``) and
    ``output2`` 1x4x15x15 (``side`` px to each side of every map point); brightness is averaged over
4 x 4 feature cells centred on each map point (64 crop px, a 32 px subject's width)."""
    cls, w1 = _channel_mix("cls", "pooled", "output1", np.stack([np.zeros(96), np.full(96, 10.0 / 255 / 96)]),
                           np.array([0.0, -5.0]))
    box, w2 = _channel_mix("box", "pooled", "output2", np.zeros((4, 96)), np.full(4, side))
    nodes = [_node("AveragePool", ["input2"], ["pooled"], kernel_shape=[4, 4], strides=[1, 1], pads=[1, 1, 1, 1]),
             cls, box]
    return _model(nodes, [_value_info("input1", (1, 96, 8, 8)), _value_info("input2", (1, 96, 16, 16))],
                  [_value_info("output1", (1, 2, 15, 15)), _value_info("output2", (1, 4, 15, 15))], [*w1, *w2])


def write_model_files(folder: Path, files: dict[str, bytes]) -> Path:
    """``folder`` holding ``files`` (relative path -> bytes); returns it."""
    for name, data in files.items():
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        (folder / name).write_bytes(data)
    return folder


def onnx_model_files(folder: Path) -> Path:
    """``folder`` holding fake VitTrack, FEAR-XS and NanoTrack v3 files in their sub-folders; returns it."""
    return write_model_files(folder, {
        "vittrack/vitTracker.onnx": vittrack_bytes(),
        "fear_xs/fear_xs_template.onnx": fear_template_bytes(),
        "fear_xs/fear_xs_search.onnx": fear_search_bytes(),
        "nanotrack_v3/nanotrack_backbone.onnx": nanotrack_v3_backbone_bytes(),
        "nanotrack_v3/nanotrack_head.onnx": nanotrack_v3_head_bytes(),
    })
