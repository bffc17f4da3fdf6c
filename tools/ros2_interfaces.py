"""The `interface list|package|show` commands of tools/ros2_lite.py: the interface files every
package installs (share/<pkg>/msg|srv|action/, listed in the ament index), printed as the real
CLI prints them (ros2interface, jazzy). No DDS: they read files."""
from __future__ import annotations

import argparse
import os
from typing import Iterator

from ament_index_python.packages import get_package_share_directory
from ament_index_python.resources import get_resource, get_resources
from rosidl_adapter.parser import parse_message_string

KINDS = ("msg", "srv", "action")
SEPARATORS = ("---",)


class UnknownInterface(LookupError):
    """Not an installed package or interface: one line on stderr, exit status 1."""


def interfaces(package: str) -> dict[str, list[str]]:
    """{kind: [Name, …]} of one package, in the index's order."""
    try:
        content, _prefix = get_resource("rosidl_interfaces", package)
    except LookupError:
        raise UnknownInterface(f"Unknown package '{package}'") from None
    found: dict[str, list[str]] = {kind: [] for kind in KINDS}
    for line in content.splitlines():
        kind, _, file_name = line.partition("/")
        name, extension = os.path.splitext(file_name)
        if kind in found and extension == f".{kind}" and name not in found[kind]:
            found[kind].append(name)
    return found


def packages() -> list[str]:
    return sorted(get_resources("rosidl_interfaces"))


def chosen_kinds(a: argparse.Namespace) -> tuple[str, ...]:
    """The kinds `-m`, `-s`, `-a` pick; all three when none is given."""
    picked = tuple(k for k, flag in zip(KINDS, (a.only_msgs, a.only_srvs, a.only_actions))
                   if flag)
    return picked or KINDS


def interface_list(a: argparse.Namespace) -> None:
    every = {p: interfaces(p) for p in packages()}
    for kind, heading in zip(KINDS, ("Messages", "Services", "Actions")):
        if kind in chosen_kinds(a):
            print(f"{heading}:")
            for package in every:
                for name in sorted(every[package][kind]):
                    print(f"    {package}/{kind}/{name}")


def interface_package(a: argparse.Namespace) -> None:
    """As the real CLI: all of them sorted (action/, msg/, srv/), or the kinds asked for in
    the order msg, srv, action."""
    found = interfaces(a.package_name)
    names = [f"{kind}/{name}" for kind in chosen_kinds(a) for name in sorted(found[kind])]
    for name in names if chosen_kinds(a) != KINDS else sorted(names):
        print(f"{a.package_name}/{name}")


def _path(name: str) -> str:
    parts = name.split("/")
    if len(parts) != 3:
        raise UnknownInterface(f"Invalid name '{name}'. Expected three parts separated by '/'")
    package, kind, type_name = parts
    if kind not in KINDS or type_name not in interfaces(package)[kind]:
        raise UnknownInterface(f"Could not find the interface '{name}'")
    return os.path.join(get_package_share_directory(package), kind, f"{type_name}.{kind}")


def _lines(name: str) -> Iterator[tuple[str, str | None, str | None, bool]]:
    """(text, nested type, trailing comment, comment-only) of each line of the file."""
    package, _kind, type_name = name.split("/")
    with open(_path(name), encoding="utf-8") as f:
        for text in (line.rstrip() for line in f):
            if text in SEPARATORS:
                yield text, None, None, False
                continue
            spec = parse_message_string(package, type_name, text)
            item = (spec.fields or spec.constants or [None])[0]
            trailing = (item.annotations.get("comment") or [None])[0] if item else None
            nested = None
            if spec.fields and "/" in str(spec.fields[0].type):
                nested = str(spec.fields[0].type).split("[", 1)[0].replace("/", "/msg/")
            yield text, nested, trailing, bool(spec.annotations.get("comment"))


def show(name: str, comments: bool, nested_comments: bool, indent: int = 0) -> None:
    """The file as it is (without comments and blank lines where not wanted), each nested
    message's definition after its field, one tab further in."""
    for text, nested, trailing, comment_only in _lines(name):
        if not comments:
            if not text or comment_only:
                continue
            if trailing:
                text = text[:text.find(trailing) - 1].strip()
        print("\t" * indent + text if text else "")
        if nested:
            show(nested, nested_comments, nested_comments, indent + 1)


def interface_show(a: argparse.Namespace) -> None:
    show(a.type, comments=not a.no_comments, nested_comments=a.all_comments)
