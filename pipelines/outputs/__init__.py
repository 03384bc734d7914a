"""Run outputs, each written incrementally and safe to interrupt: annotated video, telemetry JSONL,
CAN log, summary JSON, latency statistics and time-series plots (see docs/outputs.md)."""
