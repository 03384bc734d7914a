"""The closed loop shared by ``gimbaltrack track`` and ``simulate``: ``Loop.step(frame, t)`` gives a
``FrameRecord`` and hands it to the attached sinks (telemetry, video, plot, summary, progress)."""
from pipelines.loop.loop import OPERATOR_STOP, Loop, Subject
from pipelines.loop.record import ACQUIRING, FrameRecord
from pipelines.loop.recording import Recorder
from pipelines.loop.sinks import (
    Panel, PlotSink, ProgressSink, Sink, SummarySink, TelemetrySink, VideoSink, loop_panels, telemetry_record,
)

__all__ = ["ACQUIRING", "OPERATOR_STOP", "FrameRecord", "Loop", "Panel", "PlotSink", "ProgressSink",
           "Recorder", "Sink", "Subject", "SummarySink", "TelemetrySink", "VideoSink", "loop_panels",
           "telemetry_record"]
