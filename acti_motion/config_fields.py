"""Start-up settings as dataclass fields with documented ranges: the node shows a field's range
in its parameter's descriptor (and rclpy refuses a value outside it), and a core checks the same
ranges where it is built without ROS."""
from __future__ import annotations

import dataclasses
from typing import Any


QUEUE_SIZE_RANGE = (1, 100000)           # motions a device's queue holds
RATE_RANGE_HZ = (0.1, 1000.0)            # a node's own topics and action feedback
GOALS_RANGE = (1, 1000)                  # action goals held at once (each waits without a thread)


def ranged(default: Any, lo: float, hi: float) -> Any:
    """A config field whose value must lie within [lo, hi]."""
    return dataclasses.field(default=default, metadata={"range": (lo, hi)})


def check_ranges(config: Any, what: str) -> None:
    """ValueError naming the first field of `config` outside its range (NaN is outside)."""
    for f in dataclasses.fields(config):
        lo, hi = f.metadata.get("range", (None, None))
        value = getattr(config, f.name)
        if lo is not None and not lo <= value <= hi:
            raise ValueError(f"{what}: {f.name} is {value}: it must be within {lo:g} … {hi:g}")
