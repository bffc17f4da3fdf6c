"""The ROS-free cores log with Python's `logging` (`acti_motion`: the control loop, the motion
queue); a process that serves nodes sends those records through a node's ROS logger, so that
every line of its log has a severity, a name and a time (and reaches /rosout where the node's
logger does). A line that repeats (the same place in the code) is said at most once every
REPEAT_S; the next one that is said counts the ones held back."""
from __future__ import annotations

import logging
import math
import time
from typing import Any, Callable

REPEAT_S = 10.0


class RosLogging(logging.Handler):
    """Python log records → `logger.get_child(record.name)` (an rclpy logger), rate-limited."""

    def __init__(self, logger: Any, clock: Callable[[], float] = time.monotonic) -> None:
        super().__init__(logging.DEBUG)
        self.logger, self._clock = logger, clock
        self._said_at: dict[tuple[str, int], float] = {}
        self._held: dict[tuple[str, int], int] = {}

    def emit(self, record: logging.LogRecord) -> None:
        site, now = (record.pathname, record.lineno), self._clock()
        last = self._said_at.get(site, -math.inf)
        if now - last < REPEAT_S:
            self._held[site] = self._held.get(site, 0) + 1
            return
        self._said_at[site] = now
        text = record.getMessage()
        held = self._held.pop(site, 0)
        if held:
            text += f" ({held} more like it in the {now - last:.0f} s before, not shown)"
        # rcutils' severities are Python's levels: DEBUG 10, INFO 20, WARN 30, ERROR 40, FATAL 50
        self.logger.get_child(record.name).log(text, record.levelno)


def route_python_logging(logger: Any) -> None:
    """Send every Python log record of the process (INFO and above) through `logger`, instead
    of a handler that was routing them before."""
    root = logging.getLogger()
    for handler in [h for h in root.handlers if isinstance(h, RosLogging)]:
        root.removeHandler(handler)
    root.addHandler(RosLogging(logger))
    root.setLevel(logging.INFO)
