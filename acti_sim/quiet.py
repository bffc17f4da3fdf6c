"""Keep a library's own prints out of the process's output: a job's log is its nodes' logger
lines."""
from __future__ import annotations

import contextlib
import ctypes
import os
import sys
from typing import Iterator

_LIBC = ctypes.CDLL(None)


@contextlib.contextmanager
def output_silenced() -> Iterator[None]:
    """File descriptors 1 and 2 to /dev/null for the block (C code prints there, past
    sys.stdout): PyBullet prints its build time on stderr when imported."""
    sys.stdout.flush()
    sys.stderr.flush()
    saved = {fd: os.dup(fd) for fd in (1, 2)}
    try:
        with open(os.devnull, "w") as null:
            for fd in saved:
                os.dup2(null.fileno(), fd)
        yield
    finally:
        _LIBC.fflush(None)          # what C buffered goes to /dev/null too
        for fd, copy in saved.items():
            os.dup2(copy, fd)
            os.close(copy)
