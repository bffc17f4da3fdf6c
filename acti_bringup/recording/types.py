"""ROS types by name (`pkg/msg/Name`, `pkg/srv/Name_Event`, `pkg/action/Name_FeedbackMessage` …)
and where their definitions are installed."""
from __future__ import annotations

import importlib
import sys
from typing import Any

from ament_index_python.packages import PackageNotFoundError, get_package_share_directory


def type_class(type_name: str) -> Any:
    """The Python class of a type name; LookupError when it is not installed here."""
    parts = type_name.split("/")
    if len(parts) != 3:
        raise LookupError(f"{type_name!r} is not a type name (pkg/msg/Name)")
    package, kind, name = parts
    try:
        module = importlib.import_module(f"{package}.{kind}")
        found = getattr(module, name, None)
        if found is None and kind == "action":
            # X_FeedbackMessage, X_Goal …: beside the action X in its generated module
            base = getattr(module, name.split("_", 1)[0])
            found = getattr(sys.modules[base.__module__], name, None)
    except (ImportError, AttributeError):
        found = None
    if found is None:
        raise LookupError(f"the type {type_name} is not installed here")
    return found


def share_dir(package: str) -> str | None:
    """The package's share/ folder (None when it is not installed)."""
    try:
        return get_package_share_directory(package)
    except (PackageNotFoundError, ValueError):
        return None
