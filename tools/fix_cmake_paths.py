"""Point the ROS wheels' CMake files at this venv's Python and numpy headers.

The wheels were built under /opt/python/cp311-cp311 and name its include directories; CMake
configure of an interface package fails until they name this interpreter's. Idempotent.
"""
from __future__ import annotations

import pathlib
import sys
import sysconfig

import numpy

BUILDER_PY_INCLUDE = "/opt/python/cp311-cp311/include/python3.11"
BUILDER_NUMPY_INCLUDE = "/opt/python/cp311-cp311/lib/python3.11/site-packages/numpy/_core/include"


def main(venv: str) -> int:
    replacements = {BUILDER_PY_INCLUDE: sysconfig.get_paths()["include"],
                    BUILDER_NUMPY_INCLUDE: numpy.get_include()}
    changed = 0
    for path in pathlib.Path(venv, "share").rglob("*.cmake"):
        text = path.read_text(errors="surrogateescape")
        new = text
        for old, real in replacements.items():
            new = new.replace(old, real)
        if new != text:
            path.write_text(new, errors="surrogateescape")
            changed += 1
    print(f"fix_cmake_paths: {changed} CMake file(s) rewritten")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else ".venv"))
