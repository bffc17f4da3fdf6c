"""Print the colcon base path of our own tf2_msgs (msg_defs/tf2_msgs) when the environment has
no tf2_msgs, and nothing when it has one: the PyPI wheels lack it, a ROS install has it, and
ours must never shadow it. Run after sourcing tools/env.sh (the environment the nodes run in).

A tf2_msgs that we built earlier is removed once another one is found: install/setup.sh would
otherwise put it first on the paths."""
from __future__ import annotations

import os
import shutil
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OURS = os.path.join("msg_defs", "tf2_msgs")
MARKER = os.path.join("share", "ament_index", "resource_index", "packages", "tf2_msgs")


def installed_elsewhere() -> list[str]:
    """Prefixes on AMENT_PREFIX_PATH, other than this checkout's install/, that hold tf2_msgs."""
    ours = os.path.join(ROOT, "install") + os.sep
    return [p for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep)
            if p and not os.path.abspath(p).startswith(ours)
            and os.path.exists(os.path.join(p, MARKER))]


def main() -> None:
    found = installed_elsewhere()
    if not found:
        print(OURS)
        return
    for stale in ("install", "build"):
        path = os.path.join(ROOT, stale, "tf2_msgs")
        if os.path.isdir(path):
            shutil.rmtree(path)
    print(f"tf2_msgs found in {found[0]}: not building {OURS}", file=sys.stderr)


if __name__ == "__main__":
    main()
