"""The operator console: a page served over HTTP that shows the annotated frames, the run's
status, and lets an operator pick the subject, pause, recenter, record, retune and stop.

``ConsoleSink`` keeps the loop's newest frame (it never waits for a viewer); ``ConsoleServer``
serves it with aiohttp on a thread of its own and hands the operator's requests to a
``ConsoleOperator`` (the loop side), which runs them on the loop's thread.
"""
from pipelines.console.address import ConsoleAddress, parse_console_address
from pipelines.console.operator import ConsoleOperator, ConsoleView
from pipelines.console.server import ConsoleServer
from pipelines.console.sink import ConsoleSink

__all__ = [
           "ConsoleAddress",
           "ConsoleOperator",
           "ConsoleServer",
           "ConsoleSink",
           "ConsoleView",
           "parse_console_address",
]
