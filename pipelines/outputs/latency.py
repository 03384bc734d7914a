"""Latency statistics for the summary."""
from __future__ import annotations

from collections.abc import Iterable

import numpy as np


def latency_percentiles(latencies: Iterable[float]) -> dict[str, float | int | None]:
    """``count``, ``p50``, ``p95``, ``p99`` and ``max`` of the finite values, in their own unit.

    Percentiles interpolate linearly; with no values every statistic but ``count`` is ``None``.
    """
    values = np.asarray(list(latencies), dtype=float)
    values = values[np.isfinite(values)]
    if values.size == 0:
        return {"count": 0, "p50": None, "p95": None, "p99": None, "max": None}
    p50, p95, p99 = np.percentile(values, [50, 95, 99])
    return {"count": int(values.size), "p50": float(p50), "p95": float(p95), "p99": float(p99),
            "max": float(values.max())}
