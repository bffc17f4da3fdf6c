"""EF76–EF8E: processes (in the VM), tasks (through the host), event flags, locks, channels,
shared variables.

A blocking function looks at its arguments without taking them and returns ``WAIT`` when it
cannot proceed; the scheduler runs it again once something has changed.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from ..codes import I2, I4, INT_RANGE, Num, user_key
from ..errors import ExceptionKind as K, fail
from ..process import CYCLE_WAIT, RETRY, WAIT, Process, State
from ..values import ENTRY_BYTES
from ..variables import find
from .args import expect, function_of, integer_value, pop_count, pop_many, pop_num, pop_user

if TYPE_CHECKING:
    from ..vm import VM


def _state(proc: Process | None) -> Num:
    return Num(I2, int(proc.state) if proc is not None else 0)


def _process(vm, number: int) -> Process | None:
    """The process FXQT started under ``number``: process numbers are positive (EF76), so the
    program itself (kept as 0) is none of them and cannot be killed, suspended or restarted."""
    return vm.processes.get(number) if number > 0 else None


# ---- processes ----------------------------------------------------------------------------------
def fxqt(vm: VM, proc: Process) -> None:
    """FXQT #a b: 0 started, −1 a is not a function, −2 number not usable (≤ 0, beyond I4,
    or busy)."""
    number = pop_count(proc)
    target = function_of(proc, proc.pop())
    if target is None:
        proc.push(Num(I2, -1))
        return
    running = _process(vm, number)
    busy = running is not None and running.state is not State.DONE
    if busy or not 0 < number <= INT_RANGE[I4][1]:
        proc.push(Num(I2, -2))
        return
    frame = vm.function_frame(target, f"process {number}")
    vm.processes[number] = Process(number, frame, vm.scopes_for_new_process())
    vm.changed()
    proc.push(Num(I2, 0))


def _pop_at_least(proc: Process, lowest: int, what: str) -> int:
    """A process setting the standard gives a range (EF78 priority ≥ 1, EF7A period ≥ 0)."""
    value = pop_count(proc)
    if value < lowest:
        raise fail(K.UNDEFINED_DATA, f"{what} {value} (at least {lowest})")
    return value


def fprecd(vm: VM, proc: Process) -> None:
    """FPRECD a b: priority b (smaller runs first) for process a; the result is its state."""
    priority = _pop_at_least(proc, 1, "priority")
    target = _process(vm, pop_count(proc))
    if target is not None:
        target.priority = priority
    proc.push(_state(target))


def fcycle(vm: VM, proc: Process) -> None:
    """FCYCLE a b: process a restarts every b ms (measured from its starts; a period that
    passes while it still runs is skipped); 0 ends the cyclic start."""
    period = _pop_at_least(proc, 0, "cyclic-start period (ms)")
    target = _process(vm, pop_count(proc))
    if target is not None:
        target.period = period / 1000.0
        target.next_start = vm.host.now()
    proc.push(_state(target))


def fdone(vm: VM, proc: Process) -> None:
    proc.push(_state(_process(vm, pop_count(proc))))


def fkill(vm: VM, proc: Process) -> None:
    target = _process(vm, pop_count(proc))
    if target is None or target.state is State.DONE:
        proc.push(Num(I2, 1))
        return
    target.state = State.DONE
    target.period = 0.0
    vm.changed()
    proc.push(Num(I2, 0))


def fsuspend(vm: VM, proc: Process) -> None:
    target = _process(vm, pop_count(proc))
    if target is None or target.state in (State.DONE, State.SUSPENDED):
        proc.push(Num(I2, 1))
        return
    target.suspended_from = target.state
    target.state = State.SUSPENDED
    proc.push(Num(I2, 0))


def fresume(vm: VM, proc: Process) -> None:
    target = _process(vm, pop_count(proc))
    if target is None or target.state is not State.SUSPENDED:
        proc.push(Num(I2, 1))
        return
    target.state = target.suspended_from
    if target.blocked_at != CYCLE_WAIT:
        target.blocked_at = RETRY
    vm.changed()
    proc.push(Num(I2, 0))


# ---- tasks (outside the VM, through the host) ---------------------------------------------------
def txqt(vm: VM, proc: Process) -> None:
    proc.push(Num(I2, vm.host.start_task(pop_count(proc))))


def task_setting(setter: str):
    """TPRECD (priority), TCYCLE (period in ms): a b → the state of task a."""
    def handler(vm: VM, proc: Process) -> None:
        value = pop_count(proc)
        number = pop_count(proc)
        getattr(vm.host, setter)(number, value)
        proc.push(Num(I2, vm.host.task_state(number)))
    return handler


tprecd = task_setting("set_task_priority")
tcycle = task_setting("set_task_cycle")


def tdone(vm: VM, proc: Process) -> None:
    proc.push(Num(I2, vm.host.task_state(pop_count(proc))))


def task_control(action: str):
    """TKILL, TSUSPEND, TRESUME."""
    def handler(vm: VM, proc: Process) -> None:
        proc.push(Num(I2, vm.host.control_task(pop_count(proc), action)))
    return handler


tkill, tsuspend, tresume = (task_control(a) for a in ("kill", "suspend", "resume"))


# ---- event flags --------------------------------------------------------------------------------
def _flag_on(vm: VM, number: int) -> None:
    """A flag on: counted as data held (flags of distinct numbers in a loop grew unbounded)."""
    if number not in vm.flags:
        vm.account(ENTRY_BYTES)
        vm.flags.add(number)


def _flags_off(vm: VM, numbers) -> None:
    """Flags off. A channel is full while its flag is on (choice 37): one turned off by other
    means than CHIN (ECLR, UNLOCK, an EWAIT) is empty, its datum dropped, so that a later
    ESIG does not bring the cleared datum back."""
    for number in numbers:
        vm.flags.discard(number)
        vm.channels.pop(number, None)
    vm.changed()


MAX_FLAG = 32767    # EPOP gives a flag number as I2 (EF89)


def flag_number(item) -> int:
    """Event-flag and channel numbers are positive (EPOP uses 0 for 'no event') and fit the
    I2 that EPOP pushes."""
    number = integer_value(expect(item, Num, "an event-flag number"))
    if not 0 < number <= MAX_FLAG:
        raise fail(K.UNDEFINED_DATA, f"event flag {number:.6g} does not exist (flags are "
                                     f"1 … {MAX_FLAG}: EPOP gives them as I2)")
    return number


def _peek_flags(proc: Process) -> list[int]:
    """The flag list a1 … an n under the count, without taking it."""
    count = integer_value(expect(proc.peek(), Num, "a count"))
    if count < 0:
        raise fail(K.TYPE_MISMATCH, f"negative count {count}")
    return [flag_number(proc.peek(depth)) for depth in range(count, 0, -1)]


def _take_flags(proc: Process, count: int) -> None:
    pop_num(proc)
    pop_many(proc, count)


def lock(vm: VM, proc: Process):
    number = flag_number(proc.peek())
    if number in vm.flags:
        return WAIT
    proc.pop()
    _flag_on(vm, number)
    vm.changed()
    return None


def unlock(vm: VM, proc: Process) -> None:
    number = flag_number(proc.pop())
    if number not in vm.flags:
        proc.push(Num(I2, 1))
        return
    _flags_off(vm, [number])
    proc.push(Num(I2, 0))


def ewait(vm: VM, proc: Process):
    number = flag_number(proc.peek())
    if number not in vm.flags:
        return WAIT
    proc.pop()
    _flags_off(vm, [number])
    return None


def ewaita(vm: VM, proc: Process):
    """EWAITA: released when all flags are on at once; then all are turned off."""
    numbers = _peek_flags(proc)
    if not vm.flags.issuperset(numbers):
        return WAIT
    _take_flags(proc, len(numbers))
    _flags_off(vm, numbers)
    return None


def ewaito(vm: VM, proc: Process):
    """EWAITO: released when any flag is on; the flags that are on go to the event buffer
    (in the order given) and are turned off."""
    numbers = _peek_flags(proc)
    proc.event_buffer.clear()
    occurred = [n for n in dict.fromkeys(numbers) if n in vm.flags]
    if numbers and not occurred:
        return WAIT
    _take_flags(proc, len(numbers))
    proc.event_buffer.extend(occurred)
    _flags_off(vm, occurred)
    return None


def epop(vm: VM, proc: Process) -> None:
    """EPOP: the first event of the buffer (first in, first out), 0 when empty."""
    proc.push(Num(I2, proc.event_buffer.pop(0) if proc.event_buffer else 0))


def esig(vm: VM, proc: Process) -> None:
    _flag_on(vm, flag_number(proc.pop()))
    vm.changed()


def eclr(vm: VM, proc: Process) -> None:
    """ECLR a1 … an n: those flags off; n = 0 turns every flag off."""
    count = pop_count(proc)
    numbers = [flag_number(item) for item in pop_many(proc, count)]
    _flags_off(vm, list(vm.flags) if count == 0 else numbers)


# ---- channels -----------------------------------------------------------------------------------
def chin(vm: VM, proc: Process):
    """CHIN: wait for the flag, take the datum, flag off."""
    number = flag_number(proc.peek())
    if number not in vm.flags:
        return WAIT
    if number not in vm.channels:
        raise fail(K.UNDEFINED_DATA, f"flag {number} is on but channel {number} holds no data")
    proc.pop()
    vm.flags.discard(number)
    vm.changed()
    proc.push(vm.channels.pop(number))
    return None


def chout(vm: VM, proc: Process):
    """CHOUT a b: wait for the flag to be off, leave the datum, flag on."""
    number = flag_number(proc.peek(1))
    if number in vm.flags:
        return WAIT
    value = proc.pop()
    proc.pop()
    vm.channels[number] = value
    _flag_on(vm, number)
    vm.changed()
    return None


def share(vm: VM, proc: Process) -> None:
    """SHARE #a b: user code a (declared) is reachable by other tasks as shared variable b."""
    number = pop_count(proc)
    key = user_key(pop_user(proc).code)
    find(proc.scopes, key)
    vm.host.share(number, key)
