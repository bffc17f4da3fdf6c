"""PyBullet's physics step with the GIL released.

pybullet's `stepSimulation` holds the GIL for the whole physics step (60 … 170 µs here), so
every other thread of the job waits for it: a service's answer, `stop` on the control plane.
The step is two C calls of Bullet's client API (`b3InitStepSimulationCommand`, then
`b3SubmitClientCommandAndWaitStatus`), both exported by pybullet's module; called through
ctypes they run without the GIL. Their argument, the client's handle, lives in pybullet's own
table of clients (`sPhysicsClients1`, a static symbol): its address is read from the module's
ELF symbol table (pybullet is built from source with its symbols). `PhysicsClient` serialises
every other pybullet call against the step with its lock, as the GIL did.
"""
from __future__ import annotations

import ctypes
import mmap
import struct
from typing import Callable

import numpy as np

SYMBOL = np.dtype([("name", "<u4"), ("info", "u1"), ("other", "u1"), ("shndx", "<u2"),
                   ("value", "<u8"), ("size", "<u8")])
SHT_SYMTAB = 2
CLIENTS_TABLE = "sPhysicsClients1"        # b3PhysicsClientHandle sPhysicsClients1[MAX_PHYSICS_CLIENTS]
ANCHOR = "b3InitStepSimulationCommand"    # exported: where the module was loaded


def symbol_values(path: str, names: tuple[str, ...]) -> dict[str, int]:
    """The value (offset in the loaded module) of each named symbol of an ELF64 file's
    symbol table."""
    with open(path, "rb") as f, mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ) as elf:
        if elf[:5] != b"\x7fELF\x02" or elf[5] != 1:
            raise RuntimeError(f"{path} is not a little-endian ELF64 file")
        shoff, = struct.unpack_from("<Q", elf, 0x28)
        shentsize, shnum = struct.unpack_from("<HH", elf, 0x3A)
        sections = [struct.unpack_from("<IIQQQQIIQQ", elf, shoff + i * shentsize)
                    for i in range(shnum)]
        symtab = next((s for s in sections if s[1] == SHT_SYMTAB), None)
        if symtab is None:
            raise RuntimeError(f"{path} has no symbol table (stripped)")
        strtab = sections[symtab[6]]
        strings = elf[strtab[4]:strtab[4] + strtab[5]]
        symbols = np.frombuffer(elf[symtab[4]:symtab[4] + symtab[5]], SYMBOL)
    found = {}
    for name in names:
        at = strings.find(b"\0" + name.encode() + b"\0")
        hits = symbols["value"][symbols["name"] == at + 1] if at >= 0 else []
        if len(hits) == 0:
            raise RuntimeError(f"{path}: no symbol {name}")
        found[name] = int(hits[0])
    return found


def unlocked_step(module_path: str, client_id: int) -> Callable[[], None]:
    """The physics step of pybullet client `client_id`, as `stepSimulation` does it (without
    its optional analytics), the GIL released during both C calls."""
    lib = ctypes.CDLL(module_path)
    init, submit, can_submit = (lib.b3InitStepSimulationCommand,
                                lib.b3SubmitClientCommandAndWaitStatus, lib.b3CanSubmitCommand)
    init.restype, submit.restype = ctypes.c_void_p, ctypes.c_void_p
    init.argtypes, can_submit.argtypes = [ctypes.c_void_p], [ctypes.c_void_p]
    submit.argtypes = [ctypes.c_void_p, ctypes.c_void_p]
    values = symbol_values(module_path, (CLIENTS_TABLE, ANCHOR))
    base = ctypes.cast(init, ctypes.c_void_p).value - values[ANCHOR]
    handle = ctypes.c_void_p.from_address(
        base + values[CLIENTS_TABLE] + client_id * ctypes.sizeof(ctypes.c_void_p)).value
    if not handle or can_submit(handle) != 1:
        raise RuntimeError(f"pybullet client {client_id} not found in {CLIENTS_TABLE}")

    def step() -> None:
        if submit(handle, init(handle)) is None:
            raise RuntimeError("pybullet's step was not submitted")
    return step
