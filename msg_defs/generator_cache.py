"""The rosidl generators' output, kept by content across clones and builds.

Every new clone ran the six Python generators of the interface packages anew over ~100
interface files (the compiler's share is kept by ccache). cached_generators.cmake makes this
script the Python of the generators' commands: a command `GENERATOR --generator-arguments-file
ARGS.json ...` whose inputs (the generator's own files and templates, the .idl files, those of
the dependencies, the type descriptions) have the contents of one run before gets the files it
wrote then, copied from the cache (ACTI_GENERATED_CACHE, else ~/.cache/acti_ros2/generated/);
else it runs, and what it wrote is kept. Any other command runs as it is. The generated sources
hold no path of the clone, so a copy is what the generator would write."""
from __future__ import annotations

import hashlib
import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ARGUMENTS = "--generator-arguments-file"
NOT_OUTPUT = (".so", ".o", ".pyc")      # what the build adds later beside the generated files


def cache_dir() -> Path:
    return Path(os.environ.get("ACTI_GENERATED_CACHE")
                or Path.home() / ".cache" / "acti_ros2" / "generated")


def inputs(arguments: dict) -> list[tuple[str, Path]]:
    """(name, path) of every file the command reads, in the arguments file's order: the name
    is what is the same in every clone (the file name, or the interface's relative path)."""
    found = [(Path(p).name, Path(p)) for p in arguments.get("target_dependencies", [])]
    for field in ("idl_tuples", "ros_interface_dependencies", "type_description_tuples"):
        for item in arguments.get(field, []):
            head, _, tail = item.rpartition(":")
            path = Path(tail) if Path(tail).is_absolute() else Path(head) / tail
            found.append((tail if not Path(tail).is_absolute() else f"{head}:{path.name}", path))
    return found


def key(argv: list[str], arguments: dict) -> str | None:
    """The contents the command's output depends on, hashed; None when a file is missing."""
    digest = hashlib.sha256()
    at = argv.index(ARGUMENTS)
    flags = argv[1:at] + argv[at + 2:]
    digest.update(json.dumps([Path(argv[0]).name, flags, arguments.get("package_name")]).encode())
    for name, path in inputs(arguments):
        try:
            digest.update(name.encode() + b"\0" + path.read_bytes() + b"\0")
        except OSError:
            return None
    return digest.hexdigest()


def outputs(output_dir: Path) -> list[Path]:
    return [p for p in output_dir.rglob("*") if p.is_file() and p.suffix not in NOT_OUTPUT
            and "__pycache__" not in p.parts]


def restore(kept: Path, output_dir: Path) -> None:
    """The kept files into output_dir, as new files (newer than the inputs, so make is done)."""
    for source in outputs(kept):
        target = output_dir / source.relative_to(kept)
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(source, target)


def keep(output_dir: Path, kept: Path) -> None:
    """What the generator wrote, kept under `kept` (whole or not at all: another build may be
    keeping the same one)."""
    kept.parent.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(dir=kept.parent))
    for source in outputs(output_dir):
        target = staging / source.relative_to(output_dir)
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(source, target)
    try:
        staging.rename(kept)
    except OSError:             # kept meanwhile by another build
        shutil.rmtree(staging, ignore_errors=True)


def main(argv: list[str]) -> int:
    if ARGUMENTS not in argv or argv.index(ARGUMENTS) + 1 >= len(argv):
        os.execv(sys.executable, [sys.executable, *argv])
    with open(argv[argv.index(ARGUMENTS) + 1], encoding="utf-8") as f:
        arguments = json.load(f)
    output_dir = Path(arguments["output_dir"])
    digest = key(argv, arguments)
    kept = cache_dir() / digest if digest else None
    if kept is not None and kept.is_dir():
        restore(kept, output_dir)
        return 0
    status = subprocess.run([sys.executable, *argv]).returncode
    if status == 0 and kept is not None:
        keep(output_dir, kept)
    return status


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
