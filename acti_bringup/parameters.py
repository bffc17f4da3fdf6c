"""ROS parameters from a core's config dataclass: every field becomes a parameter of that name."""
from __future__ import annotations

import dataclasses
from typing import Any, TypeVar

from rclpy.node import Node

C = TypeVar("C")


def declare_config(node: Node, config_type: type[C]) -> C:
    """Declare one parameter per field (default = the field's default) and build the config."""
    values: dict[str, Any] = {}
    defaults = config_type()
    for f in dataclasses.fields(config_type):
        default = getattr(defaults, f.name)
        declared = list(default) if isinstance(default, tuple) else default
        value = node.declare_parameter(f.name, declared).value
        values[f.name] = tuple(value) if isinstance(default, tuple) else value
    return config_type(**values)
