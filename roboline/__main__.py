"""The RoboLine command line:

    python -m roboline compile FILE [--data POINTS] -o OUT   # code at OUT (.sasm: text form),
                                                             # the source map at OUT.map.json
    python -m roboline check FILE [--data POINTS]            # compiles, prints nothing on success

The taught data default to FILE's name with the suffix .pts, when that file exists. Exit
status: 0 compiled, 1 an error in the program or its data (printed as file:line:column, the
line and a caret), 2 a file that cannot be read.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from strolic.text import disassemble

from .compiler import compile_source
from .points import parse_points
from .program import MAP_SUFFIX, Program
from .source import Source, SourceError

POINTS_SUFFIX = ".pts"


def read_source(path: Path) -> Source:
    return Source(path.read_text(encoding="utf-8"), str(path))


def compile_file(path: Path, data: Path | None = None) -> Program:
    """A program file and its taught data (`data`, or FILE.pts beside it) → Program."""
    if data is None and path.with_suffix(POINTS_SUFFIX).exists():
        data = path.with_suffix(POINTS_SUFFIX)
    points = parse_points(read_source(data)) if data is not None else {}
    return compile_source(read_source(path), points)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m roboline", description=__doc__.split("\n\n")[0])
    commands = parser.add_subparsers(dest="command", required=True)
    for name in ("compile", "check"):
        command = commands.add_parser(name)
        command.add_argument("file", type=Path)
        command.add_argument("--data", type=Path, help="taught data (default: FILE.pts)")
        if name == "compile":
            command.add_argument("-o", "--output", type=Path, required=True)
    args = parser.parse_args(argv)
    try:
        program = compile_file(args.file, args.data)
    except SourceError as error:
        print(error.report(), file=sys.stderr)
        return 1
    except (OSError, UnicodeDecodeError) as error:
        print(f"{error}", file=sys.stderr)
        return 2
    if args.command == "compile":
        try:
            if args.output.suffix == ".sasm":
                args.output.write_text(disassemble(program.code, offsets=True))
                args.output.with_name(args.output.name + MAP_SUFFIX).write_text(
                    program.map_json())
            else:
                program.save(args.output)
        except OSError as error:
            print(f"{error}", file=sys.stderr)
            return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
