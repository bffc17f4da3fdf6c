"""`--help` of a job: its usage and every parameter of its nodes with its default, bounds and
description, in well under a second. The job's modules take seconds to import (PyBullet,
Pinocchio, TOPP-RA, viser), so the list is made once, in a child process that builds the job's
nodes out of sight (`ROS_AUTOMATIC_DISCOVERY_RANGE=OFF`: no other process sees them) and reads
what they declared, and kept in build/usage/ until a source file changes. Imports here are the
standard library's only: the help path imports nothing else."""
from __future__ import annotations

import hashlib
import importlib
import os
import subprocess
import sys
from pathlib import Path
from typing import Any, Callable

ROOT = Path(__file__).resolve().parents[2]
CACHE = ROOT / "build" / "usage"
PACKAGES = ("acti_bringup", "acti_middle_node", "vehicle_node", "acti_motion", "acti_sim",
            "acti_view", "strolic")
TAIL = ("ROS arguments: --ros-args -r __ns:=/robot1 -p name:=value "
        "--params-file config/acti_ros2.yaml (docs/interfaces.md: Parameters)")


def wants_help(args: list[str]) -> bool:
    """-h or --help among the program's own arguments (before --ros-args)."""
    own = args[1:args.index("--ros-args")] if "--ros-args" in args else args[1:]
    return bool({"-h", "--help"} & set(own))


def exit_if_help(args: list[str], doc: str, builder: str) -> None:
    """Print the usage and the parameters and exit 0 when asked for help; else return.
    `builder` is the "module:function" that builds the job's nodes (what the child runs)."""
    if not wants_help(args):
        return
    print(f"{(doc or '').strip()}\n\n{TAIL}\n\n{parameters_text(builder)}", end="")
    raise SystemExit(0)


def _sources_key(builder: str) -> str:
    """Changes when a source file (or the interpreter) does: the name of the cached list."""
    digest = hashlib.sha1(f"{builder} {sys.executable}".encode())
    for package in PACKAGES:
        for path in sorted((ROOT / package).rglob("*.py")):
            stat = path.stat()
            digest.update(f"{path} {stat.st_mtime_ns} {stat.st_size}".encode())
    return digest.hexdigest()[:16]


def _cached(builder: str) -> Path:
    return CACHE / f"{builder.replace(':', '.')}-{_sources_key(builder)}.txt"


def _keep(builder: str, text: str) -> None:
    CACHE.mkdir(parents=True, exist_ok=True)
    for old in CACHE.glob(f"{builder.replace(':', '.')}-*.txt"):
        old.unlink()
    _cached(builder).write_text(text, encoding="utf-8")


def remember_parameters(builder: str, nodes: tuple[Any, ...]) -> None:
    """Keep the list of a job that has built its nodes (no child needed for `--help` then)."""
    if not _cached(builder).exists():
        _keep(builder, describe(nodes))


def parameters_text(builder: str) -> str:
    """The parameters section, from the cache or made now (and kept)."""
    cached = _cached(builder)
    if cached.exists():
        return cached.read_text(encoding="utf-8")
    env = dict(os.environ, ROS_AUTOMATIC_DISCOVERY_RANGE="OFF")
    done = subprocess.run([sys.executable, "-m", __name__, builder], capture_output=True,
                          text=True, env=env, cwd=ROOT, timeout=300)
    if done.returncode != 0 or not done.stdout.startswith("Parameters"):
        return f"(the parameters could not be listed: {done.stderr.strip()[-500:]})\n"
    _keep(builder, done.stdout)
    return done.stdout


def _value(value: Any) -> str:
    return "[" + ", ".join(map(str, value)) + "]" if isinstance(value, (list, tuple)) \
        else repr(value) if isinstance(value, str) else str(value)


def describe(nodes: tuple[Any, ...]) -> str:
    """Each visible node's parameters: `name: default [lo … hi]  description` (the default
    as declared, whatever -p or a parameters file set)."""
    lines = ["Parameters (-p name:=value reaches every node; a --params-file section one; "
             "`ros2 param describe` says the same at run time):"]
    for node in nodes:
        if node.get_name().startswith("_"):
            continue
        lines.append(f"  {node.get_name()}:")
        for name in sorted(node._parameters):
            d = node.describe_parameter(name)
            bounds = "".join(f" [{r.from_value:g} … {r.to_value:g}]" for r in d.floating_point_range)
            bounds += "".join(f" [{r.from_value} … {r.to_value}]" for r in d.integer_range)
            value = getattr(node, "_acti_defaults", {}).get(name, node.get_parameter(name).value)
            lines.append(f"    {name}: {_value(value)}{bounds}  {d.description}".rstrip())
    return "\n".join(lines) + "\n"


def main(builder: str) -> None:
    """In the child: build the job's nodes, print what they declared, end without teardown."""
    import rclpy
    from acti_bringup.serving.spinning import declare_job_parameters
    module, function = builder.split(":")
    build: Callable[[], Any] = getattr(importlib.import_module(module), function)
    rclpy.init(args=[sys.argv[0]])
    built = build()
    nodes = built if isinstance(built, tuple) else (built,)
    declare_job_parameters(nodes)
    print(describe(nodes), end="", flush=True)
    os._exit(0)


if __name__ == "__main__":
    main(sys.argv[1])
