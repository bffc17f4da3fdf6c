"""Command line: ``python -m strolic run|asm|dis`` (see README.md)."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .codec import decode
from .errors import StrolicError
from .literals import format_value
from .text import assemble, disassemble, format_code
from .vm import VM

TEXT_SUFFIXES = {".sasm", ".txt", ".strolic"}


def load_program(path: Path) -> bytes:
    """Raw code, or the text form when the file name ends in .sasm (or .txt, .strolic)."""
    if path.suffix.lower() in TEXT_SUFFIXES:
        return assemble(path.read_text(encoding="utf-8"))
    return path.read_bytes()


def run(args: argparse.Namespace) -> None:
    """Run; the output stream goes to stderr, the final stack (--stack) to stdout; the files of
    the program (FOPEN …) are those of its directory."""
    vm = VM()
    vm.host.file_root = Path(args.program).resolve().parent
    try:
        main = vm.run(decode(load_program(Path(args.program))), budget=args.budget)
    finally:
        for data in vm.host.output:
            print("output:", " ".join(format_code(code) for code in decode(data)), file=sys.stderr)
    if args.stack:
        for item in main.stack:
            print(format_value(item))


def asm(args: argparse.Namespace) -> None:
    Path(args.output).write_bytes(assemble(Path(args.input).read_text(encoding="utf-8")))


def dis(args: argparse.Namespace) -> None:
    sys.stdout.write(disassemble(Path(args.input).read_bytes(), offsets=args.offsets))


def parser() -> argparse.ArgumentParser:
    top = argparse.ArgumentParser(prog="python -m strolic", description=__doc__)
    commands = top.add_subparsers(dest="command", required=True)
    run_parser = commands.add_parser("run", help="run a program (.sasm text or raw code)")
    run_parser.add_argument("program")
    run_parser.add_argument("--stack", action="store_true", help="print the final data stack")
    run_parser.add_argument("--budget", type=int, default=None,
                            help="stop after this many instructions")
    run_parser.set_defaults(action=run)
    asm_parser = commands.add_parser("asm", help="text form → raw code")
    asm_parser.add_argument("input")
    asm_parser.add_argument("output")
    asm_parser.set_defaults(action=asm)
    dis_parser = commands.add_parser("dis", help="raw code → text form")
    dis_parser.add_argument("input")
    dis_parser.add_argument("--offsets", action="store_true",
                            help="end each line with a comment giving the code's byte offset")
    dis_parser.set_defaults(action=dis)
    return top


def main(argv: list[str] | None = None) -> int:
    """0 on a normal end; 1 with the report on a STROLIC exception; 2 when a file fails."""
    args = parser().parse_args(argv)
    try:
        args.action(args)
    except StrolicError as error:
        print(error.report(), file=sys.stderr)
        return 1
    except (OSError, UnicodeDecodeError) as error:     # no such file; a text form not in UTF-8
        print(f"strolic: {error}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
