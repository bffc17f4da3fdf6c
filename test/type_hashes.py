"""RIHS01 type hashes of interface files, computed as a ROS 2 Jazzy build computes them: the
definitions turned into IDL by rosidl_adapter, hashed by rosidl_generator_type_description (both
Jazzy's, from the venv), with the dependencies' descriptions of the installed packages."""
from __future__ import annotations

import contextlib
import io
import json
import os
from pathlib import Path

from ament_index_python.packages import get_package_share_directory
from rosidl_adapter.action import convert_action_to_idl
from rosidl_adapter.msg import convert_msg_to_idl
from rosidl_generator_type_description import generate_type_hash

CONVERT = {".msg": convert_msg_to_idl, ".action": convert_action_to_idl}


def generator_hashes(package: str, package_dir: Path, files: list[str], work: Path,
                     dependencies: list[str]) -> dict[str, str]:
    """{type name: RIHS01 hash} of every type the interface `files` (relative to package_dir,
    e.g. "msg/JointJog.msg") define, their Goal, Result, Feedback … parts included."""
    idl_dir = work / "idl"
    idl_tuples = []
    for rel in files:
        path = Path(rel)
        with contextlib.redirect_stdout(io.StringIO()):      # it says what it reads and writes
            CONVERT[path.suffix](package_dir, package, path, idl_dir / path.parent)
        idl_tuples.append(f"{idl_dir}:{path.with_suffix('.idl')}")
    arguments = work / "arguments.json"
    arguments.write_text(json.dumps({
        "package_name": package, "output_dir": str(work / "out"), "idl_tuples": idl_tuples,
        "include_paths": [f"{d}:{get_package_share_directory(d)}" for d in dependencies]}))
    hashes: dict[str, str] = {}
    for generated in generate_type_hash(str(arguments)):
        for entry in json.loads(Path(generated).read_text())["type_hashes"]:
            if entry["type_name"].startswith(package + "/"):
                hashes[entry["type_name"]] = entry["hash_string"]
    return hashes


def installed_hashes(package: str, files: list[str]) -> dict[str, str]:
    """The hashes the installed `package` (ours where we built it, else the environment's)
    declares for the types of `files`."""
    share = Path(get_package_share_directory(package))
    hashes: dict[str, str] = {}
    for rel in files:
        description = json.loads((share / Path(rel).with_suffix(".json")).read_text())
        for entry in description["type_hashes"]:
            if entry["type_name"].startswith(package + "/"):
                hashes[entry["type_name"]] = entry["hash_string"]
    return hashes


def interface_files(package_dir: Path) -> list[str]:
    return sorted(str(p.relative_to(package_dir)) for kind in ("msg", "action", "srv")
                  for p in (package_dir / kind).glob(f"*.{kind}") if os.path.isfile(p))
