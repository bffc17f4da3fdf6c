"""EE0A–EE0D: communication port settings and digital I/O, through the host's hooks.

Port numbers may be reals (rounded); data and masks are bit patterns, so they must be integers.
A port that does not exist is a console warning (the program goes on), as the standard says.
"""
from __future__ import annotations

import math
from typing import TYPE_CHECKING

from ..codes import I2, Num, wrap_int
from ..errors import ExceptionKind as K, fail
from ..host import PortSettings
from ..process import WAIT, Process
from .args import expect, integer_value, pop_count, pop_int

if TYPE_CHECKING:
    from ..vm import VM

SPEEDS = {1: 300, 2: 1200, 3: 2400, 4: 4800, 5: 9600, 6: 19200}
STOP_BITS = {1: 1, 2: 1.5, 3: 2}
FLOW_BITS, FRAME_BITS = 0b11, 0b101111
IO_POLL = 0.001          # seconds between two looks at an input while IOWAIT waits


def cnfg(vm: VM, proc: Process) -> None:
    """CNFG a b c d: port a, flow/RS control b, speed code c, frame format d; an invalid value
    (an unlisted bit, speed code, stop-bit code 0, no such port) is a warning, nothing is set."""
    frame = pop_count(proc)
    speed = pop_count(proc)
    flow = pop_count(proc)
    port = pop_count(proc)
    if flow & ~FLOW_BITS or frame & ~FRAME_BITS or not frame & 0b11 or speed not in SPEEDS:
        vm.host.warn(f"CNFG: invalid setting for port {port} (b={flow}, c={speed}, d={frame}); "
                     "nothing is set")
        return
    settings = PortSettings(flow_control=bool(flow & 1), rs_control=bool(flow & 2),
                            speed=SPEEDS[speed], data_bits=8 if frame & 0b100000 else 7,
                            parity=("even" if frame & 0b100 else "odd") if frame & 0b1000
                            else "none", stop_bits=STOP_BITS[frame & 0b11])
    if not vm.host.configure_port(port, settings):
        vm.host.warn(f"CNFG: communication port {port} does not exist; nothing is set")


def _port_bits(vm: VM, port: int, output: bool, function: str) -> int | None:
    bits = vm.host.io_port_bits(port, output)
    if bits is None:
        kind = "output" if output else "input"
        vm.host.warn(f"{function}: {kind} port {port} does not exist")
    return bits


def _as_i2(value: int) -> Num:
    """A port value as I2: the bit pattern (a 16-bit value ≥ 0x8000 is negative)."""
    return wrap_int(I2, value)


def dout(vm: VM, proc: Process) -> None:
    """DOUT a b: the low-order bits of b (as many as the port is wide) to port a."""
    data = pop_int(proc).value
    port = pop_count(proc)
    bits = _port_bits(vm, port, True, "DOUT")
    if bits is not None:
        vm.host.write_io(port, data & ((1 << bits) - 1))
        vm.changed()                       # an IOWAIT on a wired-back input may proceed


def din(vm: VM, proc: Process) -> None:
    """DIN a: the value of port a as I2 (high-order bits 0 for an 8-bit port); I2 0 and a
    warning when the port does not exist."""
    port = pop_count(proc)
    bits = _port_bits(vm, port, False, "DIN")
    proc.push(_as_i2(vm.host.read_io(port) & ((1 << bits) - 1)) if bits is not None
              else Num(I2, 0))


def iowait(vm: VM, proc: Process):
    """IOWAIT a b c d: wait until the bits of mask b read from port a are all on (c = 1) or one
    is on (c = 2), or for d ms (d = 0: look once, d < 0: no limit); pushes the masked value
    and the timeout flag (1 when the time ran out or the port does not exist)."""
    timeout = expect(proc.peek(), Num, "a timeout").value
    condition = integer_value(expect(proc.peek(1), Num, "a wait condition"))
    mask = expect(proc.peek(2), Num, "a mask")
    port = integer_value(expect(proc.peek(3), Num, "a port number"))
    if not mask.is_integer:
        raise fail(K.TYPE_MISMATCH, "the mask of IOWAIT must be an integer")
    if condition not in (1, 2):
        raise fail(K.UNDEFINED_DATA, f"wait condition {condition} (1 all bits, 2 any bit)")
    bits = _port_bits(vm, port, False, "IOWAIT")
    if bits is None:
        return _iowait_done(proc, 0, True)
    mask_value = mask.value & ((1 << bits) - 1)
    masked = vm.host.read_io(port) & mask_value
    if (masked == mask_value) if condition == 1 else masked != 0:
        return _iowait_done(proc, masked, False)
    seconds = timeout / 1000.0 if timeout >= 0 else math.inf
    if vm.timed_wait(proc, seconds, IO_POLL) is WAIT:
        return WAIT
    return _iowait_done(proc, masked, True)


def _iowait_done(proc: Process, masked: int, timed_out: bool) -> None:
    del proc.stack[-4:]
    proc.timed = None
    proc.push(_as_i2(masked))
    proc.push(Num(I2, int(timed_out)))
