"""EF6C–EF75: identification, INIT, trace, and the exchange with the programming device."""
from __future__ import annotations

from typing import TYPE_CHECKING

from .. import literals
from ..codes import ACK_CODE, DATA_TYPES, Str
from ..errors import ExceptionKind as K, fail
from ..host import OUTPUT_ENTRY
from ..process import Process, State
from ..values import encode_value

if TYPE_CHECKING:
    from ..vm import VM

VERSION_ID = b"STROLIC JIS B 8440-1994"      # the prefix EF6C requires, as printed
SYSTEM_ID = b"acti_ros2 strolic 0.1 (Python STROLIC virtual machine, acti_ros2 project)"


def verid(vm: VM, proc: Process) -> None:
    proc.push(Str(VERSION_ID))


def sysid(vm: VM, proc: Process) -> None:
    proc.push(Str(SYSTEM_ID))


def init(vm: VM, proc: Process) -> None:
    """INIT: stacks, variables, heap, nesting, ε, trace, configuration, flags, channels and all
    processes are reset; the program continues with the next code of the input stream."""
    main = vm.main
    vm.reset()
    vm.processes = {0: main}
    main.stack.clear()
    main.returns.clear()
    main.scopes[:] = [vm.globals]
    main.event_buffer.clear()
    if main.state is State.WAITING and main.frame is main.root:
        main.root.pc += 1                 # the code main waited in is abandoned
    main.frame = main.root
    main.state = State.RUNNING
    if proc is not main:
        proc.state = State.DONE


def tron(vm: VM, proc: Process) -> None:
    vm.trace = True


def troff(vm: VM, proc: Process) -> None:
    vm.trace = False


def trace(vm: VM, proc: Process) -> None:
    """TRACE: the item goes to the console in the text form when the trace flag is on."""
    item = proc.pop()
    if vm.trace:
        vm.host.console(f"TRACE {literals.format_value(item)}")


def send(vm: VM, data: bytes) -> None:
    """To the output stream, which the host keeps (memory_limit)."""
    vm.claim(len(data) + OUTPUT_ENTRY)
    vm.host.send(data)


def sync(vm: VM, proc: Process) -> None:
    """SYNC: this VM is always in a normal state, so the answer is ACK."""
    send(vm, ACK_CODE.to_bytes(2, "big"))


def reply_code(vm: VM, proc: Process) -> None:
    """ACK, NAK: replies to the host, never executed; received in a program they are ignored."""


def result(vm: VM, proc: Process) -> None:
    """RESULT: the value, as a tagged data code, on the output stream."""
    value = proc.pop()
    if not isinstance(value, DATA_TYPES):
        raise fail(K.TYPE_MISMATCH, "RESULT sends data only")
    send(vm, encode_value(value))
