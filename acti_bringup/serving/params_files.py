"""A parameters file (`--params-file`) none of whose sections names a node of the job is
ignored by rcl without a word (a file written for `/robot1/…` given to a job in `/robot2`, or
for `acti_middle_node` given to a namespaced one): the job says so, naming the file's sections
and its own nodes."""
from __future__ import annotations

from typing import Any, Callable, Iterable

import yaml
from rclpy.node import Node


def params_files(args: list[str]) -> list[str]:
    """The paths given as `--params-file PATH` among the ROS arguments."""
    found, in_ros = [], False
    for i, arg in enumerate(args):
        if arg == "--ros-args":
            in_ros = True
        elif arg == "--":
            in_ros = False
        elif in_ros and arg == "--params-file" and i + 1 < len(args):
            found.append(args[i + 1])
    return found


def _flat(values: Any, prefix: str = "") -> dict[str, Any]:
    """{"a.b": v} of a nested mapping of parameters, as rcl names them."""
    if not isinstance(values, dict):
        return {prefix: values}
    out: dict[str, Any] = {}
    for key, value in values.items():
        out.update(_flat(value, f"{prefix}.{key}" if prefix else str(key)))
    return out


def _same(given: Any, value: Any) -> bool:
    if isinstance(given, (list, tuple)) or hasattr(given, "tolist"):
        return list(given) == list(value) if isinstance(value, (list, tuple)) else False
    return given == value


def _section_applied(section: Any, nodes: Iterable[Node]) -> bool:
    """Some node of the job took one of the section's values as a start-up override."""
    params = _flat((section or {}).get("ros__parameters", {}) if isinstance(section, dict) else {})
    return any(name in overrides and _same(overrides[name].value, value)
               for overrides in (getattr(n, "_parameter_overrides", {}) for n in nodes)
               for name, value in params.items())


def warn_of_unmatched_files(nodes: tuple[Node, ...], args: list[str],
                            warn: Callable[[str], None]) -> None:
    """Warn of each parameters file that no node of the job took anything from."""
    names = ", ".join(n.get_fully_qualified_name() for n in nodes)
    for path in params_files(args):
        try:
            with open(path, encoding="utf-8") as f:
                sections = yaml.safe_load(f) or {}
        except (OSError, yaml.YAMLError):
            continue                # rcl refused it already at init
        if not isinstance(sections, dict) or any(_section_applied(s, nodes)
                                                 for s in sections.values()):
            continue
        warn(f"{path}: none of its sections ({', '.join(map(str, sections))}) is a node of "
             f"this job ({names}), so none of its parameters is used (a section names a node: "
             "/**/vehicle_node for any namespace, /robot1/vehicle_node for one)")
