"""One line naming the machine a benchmark ran on, printed beside its figures.

Figures move with the CPU: ``cv2.dnn`` ran NanoTrack markedly slower on an AMD EPYC without
AVX-512 than on an earlier machine of the same kind (docs/tracker-lab.md), so every table says
where it was measured.
"""
from __future__ import annotations

import os
import platform
from pathlib import Path

import cv2
import numpy as np


def _cpuinfo_value(key: str) -> str | None:
    """The first ``key : value`` of /proc/cpuinfo (Linux), None elsewhere."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.split(":", 1)[0].strip() == key:
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return None


def cpu_model() -> str:
    """The CPU's model name (/proc/cpuinfo on Linux, else what ``platform`` knows)."""
    return _cpuinfo_value("model name") or platform.processor() or platform.machine() or "unknown CPU"


def simd_level() -> str:
    """The widest x86 vector extension the CPU reports (OpenCV dispatches to AVX2 and AVX-512)."""
    flags = (_cpuinfo_value("flags") or "").split()
    if "avx512f" in flags:
        return "AVX-512"
    if "avx2" in flags:
        return "AVX2 (no AVX-512)"
    return "no AVX2 reported"


def describe_machine() -> str:
    """E.g. ``machine: AMD EPYC, 2 CPUs, AVX2 (no AVX-512); OpenCV 4.14.0, numpy 2.4.6``."""
    return (f"machine: {cpu_model()}, {os.cpu_count()} CPUs, {simd_level()}; "
            f"OpenCV {cv2.__version__}, numpy {np.__version__}")
