"""Loading ONNX networks into onnxruntime sessions, checked against the shapes a tracker expects.

onnxruntime runs these small networks faster than ``cv2.dnn`` on one CPU thread and reads every
operator they use (docs/tracker-lab.md); sessions get one intra-op thread by default, since the tracking loop shares
the machine with decoding, control and the bus.
"""
from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np

DEFAULT_THREADS = 1  # intra-op threads per session

Shape = tuple[int, ...]


class RuntimeMissingError(ValueError):
    """A model tracker asked for where its runtime is not installed."""


class OnnxNetwork:
    """One network on onnxruntime: ``run(**inputs)`` gives its outputs by name, as float32 arrays."""

    def __init__(self, path: Path, what: str, inputs: Mapping[str, Shape], outputs: Mapping[str, Shape],
                 threads: int = DEFAULT_THREADS) -> None:
        """Load ``path`` and check it by one run on zeros: ``ValueError`` naming the file (as ``what``)
        when it is no ONNX network, or not one taking ``inputs`` and giving ``outputs`` of these shapes;
        ``RuntimeMissingError`` (a ``ValueError``: the tracker asked for cannot run here, which the
        CLI reports in one line) when onnxruntime is not installed."""
        try:
            import onnxruntime  # here, not at the top: only the model trackers need it
        except ImportError as exc:
            raise RuntimeMissingError(f"{what} runs on onnxruntime, which is not installed here "
                                      "(pip install onnxruntime), or choose --tracker dcf") from exc

        if threads < 1:
            raise ValueError(f"threads must be at least 1, not {threads}")
        options = onnxruntime.SessionOptions()
        options.intra_op_num_threads = threads
        options.inter_op_num_threads = 1
        options.log_severity_level = 3  # its warnings are about graph optimisations, not our input
        self.path = path
        try:
            self._session = onnxruntime.InferenceSession(str(path), options, providers=["CPUExecutionProvider"])
        except Exception as exc:  # onnxruntime raises its own exception types for bad files
            raise ValueError(f"{what} {path}: not a readable ONNX network (damaged or another file?)") from exc
        self._outputs = list(outputs)
        try:
            got = self.run(**{name: np.zeros(shape, np.float32) for name, shape in inputs.items()})
        except Exception as exc:
            raise ValueError(f"{what} {path}: not the expected network (it must take "
                             f"{_describe(inputs)})") from exc
        shapes = {name: value.shape for name, value in got.items()}
        if shapes != {name: tuple(shape) for name, shape in outputs.items()}:
            raise ValueError(f"{what} {path}: not the expected network (it gives {_describe(shapes)}, "
                             f"not {_describe(outputs)})")

    def run(self, **inputs: np.ndarray) -> dict[str, np.ndarray]:
        """The outputs by name for ``inputs`` by name."""
        values = self._session.run(self._outputs, {k: np.ascontiguousarray(v, np.float32) for k, v in inputs.items()})
        return dict(zip(self._outputs, values))


def _describe(shapes: Mapping[str, Shape]) -> str:
    return ", ".join(f"{name} {'x'.join(str(d) for d in shape)}" for name, shape in shapes.items())
