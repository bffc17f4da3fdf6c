"""Print the colcon base paths of our own standard interface packages (msg_defs/tf2_msgs,
msg_defs/control_msgs) that the environment lacks, one per line, and nothing for those it has:
the PyPI wheels lack them, a ROS install has them, and ours must never shadow one. Run after
sourcing tools/env.sh (the environment the nodes run in).

A package of ours that we built earlier is removed once another one is found: install/setup.sh
would otherwise put it first on the paths."""
from __future__ import annotations

import os
import shutil
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OWN_PACKAGES = ("tf2_msgs", "control_msgs")       # each in msg_defs/<name>


def marker(package: str) -> str:
    """The ament index entry an install of `package` has, relative to its prefix."""
    return os.path.join("share", "ament_index", "resource_index", "packages", package)


def installed_elsewhere(package: str) -> list[str]:
    """Prefixes on AMENT_PREFIX_PATH, other than this checkout's install/, that hold `package`."""
    ours = os.path.join(ROOT, "install") + os.sep
    return [p for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep)
            if p and not os.path.abspath(p).startswith(ours)
            and os.path.exists(os.path.join(p, marker(package)))]


def own_base_paths() -> list[str]:
    """msg_defs/<name> of each package no other prefix has; builds of ours that another
    prefix now shadows are removed."""
    paths = []
    for package in OWN_PACKAGES:
        found = installed_elsewhere(package)
        if not found:
            paths.append(os.path.join("msg_defs", package))
            continue
        for stale in ("install", "build"):
            path = os.path.join(ROOT, stale, package)
            if os.path.isdir(path):
                shutil.rmtree(path)
        print(f"{package} found in {found[0]}: not building msg_defs/{package}", file=sys.stderr)
    return paths


if __name__ == "__main__":
    print("\n".join(own_base_paths()))
