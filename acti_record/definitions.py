"""Complete message definitions in rosbag2's `ros2msg` encoding: the type's own text first, then
every type it uses, each after a line of 80 `=` and `MSG: pkg/kind/Name` (rosbag2's
docs/message_definition_encoding.md), read from the `.msg`, `.srv` and `.action` files the
packages install under share/.

The parts of services and actions (`X_Request`, `X_Goal` …) come from their `.srv`/`.action`
file; the wrappers rosidl generates around them (a service's `X_Event`, an action's
`X_SendGoal_Request`, `X_FeedbackMessage` …) have a fixed shape, written here as a table. A
service event is given its own definition, not rosbag2 Jazzy's `SRV:` text of the service,
so that readers that decode from the schema (rosbags, Foxglove) can read it."""
from __future__ import annotations

import os
import re
from typing import Callable

SEPARATOR = "=" * 80
PRIMITIVES = {"bool", "byte", "char", "float32", "float64", "int8", "uint8", "int16", "uint16",
              "int32", "uint32", "int64", "uint64", "string", "wstring"}
_FIELD_TYPE = re.compile(r"^\s*([A-Za-z][\w/]*)(?:<=\d+)?(?:\[[^\]]*\])?\s+\w", re.M)
_CONSTANT = re.compile(r"^\s*\S+\s+\w+\s*=")

# The shapes rosidl gives the types it generates around a service's and an action's parts:
# suffix: (the kinds that have it, the shape; `{base}` is the type without the suffix).
GENERATED = {
    "_Event": (("srv", "action"), "service_msgs/msg/ServiceEventInfo info\n"
               "{base}_Request[<=1] request\n{base}_Response[<=1] response\n"),
    "_SendGoal_Request": (("action",), "unique_identifier_msgs/msg/UUID goal_id\n{base}_Goal goal\n"),
    "_SendGoal_Response": (("action",), "bool accepted\nbuiltin_interfaces/msg/Time stamp\n"),
    "_GetResult_Request": (("action",), "unique_identifier_msgs/msg/UUID goal_id\n"),
    "_GetResult_Response": (("action",), "int8 status\n{base}_Result result\n"),
    "_FeedbackMessage": (("action",), "unique_identifier_msgs/msg/UUID goal_id\n"
                         "{base}_Feedback feedback\n"),
}
# the parts of a .srv / .action file, in order, separated by `---`
PARTS = {"srv": ("_Request", "_Response"), "action": ("_Goal", "_Result", "_Feedback")}

ShareDir = Callable[[str], "str | None"]


class DefinitionNotFound(LookupError):
    """No installed file defines the type."""


def full_text(type_name: str, share_dir: ShareDir) -> str:
    """The complete `ros2msg` definition of `pkg/kind/Name`. `share_dir(pkg)`: where the package
    installed its share/ files (None when it is not installed)."""
    texts: dict[str, str] = {}
    order: list[str] = []

    def visit(name: str) -> None:
        if name in texts:
            return
        texts[name] = text = own_text(name, share_dir)
        order.append(name)
        for dep in dependencies(text, name):
            visit(dep)
    visit(type_name)
    return texts[type_name] + "".join(f"\n{SEPARATOR}\nMSG: {n}\n{texts[n]}" for n in order[1:])


def own_text(type_name: str, share_dir: ShareDir) -> str:
    """The definition of one type alone: its `.msg` file, its part of a `.srv`/`.action` file,
    or the shape of a generated wrapper."""
    package, kind, name = split(type_name)
    for suffix, (kinds, shape) in GENERATED.items():
        if kind in kinds and name.endswith(suffix):
            return shape.format(base=f"{package}/{kind}/{name.removesuffix(suffix)}")
    if kind == "msg":
        return _read(share_dir, package, "msg", f"{name}.msg")
    for index, suffix in enumerate(PARTS.get(kind, ())):
        if name.endswith(suffix):
            whole = _read(share_dir, package, kind, f"{name.removesuffix(suffix)}.{kind}")
            parts = re.split(r"^---\s*$\n?", whole, flags=re.M)
            if len(parts) == len(PARTS[kind]):
                return parts[index]
    raise DefinitionNotFound(type_name)


def split(type_name: str) -> tuple[str, str, str]:
    """(package, kind, name) of `pkg/kind/Name` (`pkg/Name` is a message)."""
    parts = type_name.split("/")
    if len(parts) == 2:
        parts.insert(1, "msg")
    if len(parts) != 3 or not all(parts):
        raise DefinitionNotFound(f"{type_name!r} is not a type name (pkg/msg/Name)")
    return parts[0], parts[1], parts[2]


def dependencies(text: str, type_name: str) -> list[str]:
    """The types `text` (the definition of `type_name`) uses, as full names, in order of use;
    a name without a package is a message of the same package."""
    package, kind, _ = split(type_name)
    found: list[str] = []
    for used in _FIELD_TYPE.findall(_without_comments(text)):
        if used in PRIMITIVES:
            continue
        if used == "Header":
            full = "std_msgs/msg/Header"
        elif "/" not in used:
            full = f"{package}/msg/{used}"
        else:
            full = "/".join(split(used))
        if full not in found:
            found.append(full)
    return found


def _without_comments(text: str) -> str:
    """The field lines only: comments and constants (`TYPE NAME=VALUE`) removed."""
    lines = (line.split("#", 1)[0] for line in text.splitlines())
    return "\n".join(line for line in lines if not _CONSTANT.match(line))


def _read(share_dir: ShareDir, package: str, folder: str, file: str) -> str:
    root = share_dir(package)
    path = os.path.join(root, folder, file) if root else ""
    if not path or not os.path.isfile(path):
        raise DefinitionNotFound(f"{package}/{folder}/{file}")
    with open(path, encoding="utf-8") as f:
        return f.read()
