"""The intermediate-code machine of Reference 1: compiling codes, scheduler, dispatch.

Processes are scheduled cooperatively: the runnable process with the smallest priority number
runs for a slice; a blocking function (LOCK, EWAIT, CHIN …) returns ``WAIT`` and is retried
when something changed.
"""
from __future__ import annotations

import numpy as np

from . import opcodes
from .codec import CodeKind, decode, decode_function
from .codes import DATA_TYPES, Function, Num, UserCode, is_user_code, user_code_of, user_key
from .errors import ExceptionKind as K, StrolicError, fail
from .host import Host
from .interrupts import Interrupts
from .process import (BUILTIN, CYCLE_WAIT, INDIRECT, PUSH, USER, WAIT, Frame, Process,
                      State)
from .values import ENTRY_BYTES, check_datum_size, data_of
from .variables import Scope, find

SLICE = 200              # instructions a process runs before the scheduler looks again
INTERRUPT_PRIORITY = float("-inf")   # interrupt processes go before every process
DEFAULT_EPS = 1e-6
MAX_BODY = 1 << 19       # bytes of a function body compiled: at most 256 Ki codes (about 40 MB)
INSTRUCTION_BYTES = 160  # memory one compiled code takes, counted against memory_limit


class VM:
    """Runs a decoded program; the state parameters of Reference 1 §2(6) live here."""

    def __init__(self, host: Host | None = None, *, max_stack: int = 100_000,
                 max_return_depth: int = 10_000, max_nesting: int = 32,
                 heap_limit: int = 1 << 24, memory_limit: int = 1 << 27) -> None:
        self.host = host or Host()
        self.max_stack = max_stack
        self.max_return_depth = max_return_depth
        self.max_nesting = max_nesting
        self.heap_limit = heap_limit
        self.memory_limit = memory_limit   # bytes of data held at once (stacks, heap, output)
        self.made = 0                      # bytes of data made since memory was last measured
        self._compiled: dict[bytes, list] = {}
        self._compiled_bytes = 0           # bytes of the bodies in _compiled
        self.generation = 0                # bumped whenever waiting processes may proceed
        self.executed = 0                  # instructions of the current run (budget)
        self.in_slice = 0                  # … and of the slice a host function blocks in
        self.budget: int | None = None
        self.main: Process | None = None   # process 0, the program of the current run
        self.files: dict = {}              # file number → open file (functions/system_files.py)
        self.reset()

    # ---- state ----------------------------------------------------------------------------------
    def reset(self) -> None:
        """Everything INIT initialises (EF6E)."""
        self.globals = Scope(0)
        self.eps = DEFAULT_EPS
        self.trace = False
        self.configuration = 0             # SCONF bits (RIGHTY/LEFTY, ABOVE/BELOW, FLIP/NOFLIP)
        self.elbow = 0.0                   # arm angle of a 7-axis arm, degree
        self.flags: set[int] = set()       # event flags that are on
        self.channels: dict[int, object] = {}
        self.processes: dict[int | str, Process] = {}
        self.interrupts = Interrupts()
        self.close_files()

    def close_files(self, report: bool = False) -> None:
        """At INIT and at the end of every run: the files the program left open are closed;
        with ``report`` (a run that ended normally) a failure is raised once all are closed."""
        files, self.files = self.files, {}
        failure = None
        for file in files.values():
            try:
                file.close()
            except StrolicError as error:
                failure = failure or error
        if failure is not None and report:
            raise failure

    def changed(self) -> None:
        self.generation += 1

    def timed_wait(self, proc: Process, seconds: float, poll: float | None = None):
        """For a blocking function that gives up after ``seconds`` (∞: never): ``None`` once that
        time has passed since its first attempt, else ``WAIT``, the process looking again when
        something changes, after ``poll`` seconds (a condition outside the VM) or at the end."""
        key = (proc.frame, proc.frame.pc)
        now = self.host.now()
        if proc.timed is None or proc.timed[0] != key:
            proc.timed = (key, now + seconds)
        end = proc.timed[1]
        if now >= end:
            proc.timed = None
            return None
        proc.wake_at = min(end, now + poll) if poll is not None else end
        return WAIT

    # ---- memory ---------------------------------------------------------------------------------
    def heap_in_use(self) -> int:
        """Bytes of the registrations of every scope, shadowed ones included (choice 24)."""
        return sum(b.size() or 0 for b in self._registrations())

    def _registrations(self) -> list:
        scopes = [self.globals] + [s for p in self.processes.values() for s in p.scopes[1:]]
        return [b for s in scopes for stack in s.table.values() for b in stack]

    def memory_in_use(self) -> int:
        """Bytes of data held: the data stacks and channels (a datum shared by DUP counted once),
        the heap, ENTRY_BYTES a registration and a flag that is on, and what the host keeps for
        the program."""
        items = [*(item for p in self.processes.values() for item in p.stack),
                 *self.channels.values()]
        held = {id(item): item for item in items if isinstance(item, DATA_TYPES)}
        registrations = self._registrations()
        return (sum(len(data_of(item)) for item in held.values())
                + sum(b.size() or 0 for b in registrations)
                + (len(registrations) + len(self.flags)) * ENTRY_BYTES
                + self.host.memory_in_use() + self.code_in_use())

    def code_in_use(self) -> int:
        """Bytes of the compiled bodies cached or executing (a frame or a return destination)."""
        frames = [p.frame for p in self.processes.values()] + [
            frame for p in self.processes.values() for kind, frame in p.returns if kind == "call"]
        held = {id(codes): codes for codes in self._compiled.values()}
        held.update((id(frame.codes), frame.codes) for frame in frames)
        return sum(map(len, held.values())) * INSTRUCTION_BYTES

    def claim(self, size: int) -> None:
        """A function makes a datum of ``size`` bytes: refused when the data held would pass
        ``memory_limit`` (a loop piling up copies of a large string)."""
        check_datum_size(size)
        self.account(size)

    def account(self, size: int) -> None:
        """``size`` bytes more are held; what is held is measured only when the bytes made since
        the last measurement could pass ``memory_limit``."""
        self.made += size
        if self.made > self.memory_limit:
            self.made = self.memory_in_use() + size
            if self.made > self.memory_limit:
                raise fail(K.MEMORY_EXHAUSTED, f"{self.made} bytes of data would be held "
                                               f"(at most {self.memory_limit})")

    def scopes_for_new_process(self) -> list[Scope]:
        return [self.globals]

    # ---- compiling codes into instructions ------------------------------------------------------
    def compile(self, codes: list, origin: int = 0) -> list:
        """Instructions (op, argument, offset in the body, size) from decoded codes."""
        instructions = []
        for code in codes:
            offset = code.offset - origin
            if code.kind is CodeKind.CALL:
                if is_user_code(code.value):
                    instruction = (USER, user_key(code.value), offset, code.size)
                else:
                    instruction = (BUILTIN, opcodes.BY_CODE[code.value], offset, code.size)
            elif code.kind is CodeKind.INDIRECT:
                instruction = (INDIRECT, user_key(code.value), offset, code.size)
            else:
                instruction = (PUSH, code.value, offset, code.size)
            instructions.append(instruction)
        return instructions

    def function_frame(self, function: Function, name: str) -> Frame:
        """A frame for a function body; bodies are compiled once (offsets relative to the body)."""
        codes = self._compiled.get(function.body)
        if codes is None:
            codes = self._compile_body(function)
        return Frame(codes, function.origin, function, name)

    def _compile_body(self, function: Function) -> list:
        """A body made at run time (EMBB into an Fn area) may be megabytes, and a code takes
        about INSTRUCTION_BYTES compiled: too long a body is refused before it is decoded, the
        compiled code counts against memory_limit, and the cache is emptied once it holds more
        than MAX_BODY bytes of bodies (a loop calling ever new bodies)."""
        body = function.body
        if len(body) > MAX_BODY:
            raise fail(K.MEMORY_EXHAUSTED, f"function data of {len(body)} bytes cannot be "
                                           f"executed (at most {MAX_BODY})")
        self.account(len(body) // 2 * INSTRUCTION_BYTES)
        if self._compiled_bytes + len(body) > MAX_BODY:
            self._compiled.clear()
            self._compiled_bytes = 0
        codes = self._compiled[body] = self.compile(decode_function(function),
                                                    function.origin or 0)
        self._compiled_bytes += len(body)
        return codes

    # ---- running --------------------------------------------------------------------------------
    def run(self, program: bytes | list, budget: int | None = None) -> Process:
        """Run a program (bytes or decoded codes) to its end; returns the main process.

        Raises StrolicError for every exception state; ``budget`` bounds the instructions."""
        codes = decode(program) if isinstance(program, (bytes, bytearray)) else program
        main = Process(0, Frame(self.compile(codes), 0, None, "program"), [self.globals])
        self.main = main
        self.processes = {0: main}
        self.budget = budget
        self.executed = 0
        self.made = 0
        # numbers that overflow are the program's exceptions (checked as results are made), not
        # numpy's warnings on the process's stderr
        with np.errstate(over="ignore", invalid="ignore"):
            try:
                while main.state is not State.DONE:
                    self.interrupts.poll(self)
                    try:
                        self.host.check(self)
                    except StrolicError as error:
                        raise self._at_main(error)
                    proc = self._pick()
                    if proc is None:
                        self._idle()
                        continue
                    self._execute(proc, SLICE)
                self.close_files(report=True)
            except StrolicError as error:
                self.host.stop(error)
                raise
            finally:
                self.close_files()
        return main

    def _eligible(self, proc: Process, now: float | None) -> bool:
        if proc.state is State.RUNNING:
            return True
        if proc.state is State.WAITING:
            if proc.period and proc.blocked_at == CYCLE_WAIT:
                return now is not None and now >= proc.next_start
            if proc.wake_at is not None and now is not None and now >= proc.wake_at:
                return True
            return proc.blocked_at != self.generation
        return False

    def _pick(self) -> Process | None:
        timed = any(p.period or p.wake_at is not None for p in self.processes.values())
        now = self.host.now() if timed else None
        best = None
        for proc in self.processes.values():
            if self._eligible(proc, now) and (best is None or (proc.priority, proc.last_run)
                                              < (best.priority, best.last_run)):
                best = proc
        if best is not None and best.state is State.WAITING:
            best.wake_at = None
            if best.blocked_at == CYCLE_WAIT:
                best.restart()
            else:
                best.state = State.RUNNING
        return best

    def _due_times(self) -> list[float]:
        """Host times at which a waiting process may proceed (cyclic starts, timed waits)."""
        due = []
        for proc in self.processes.values():
            if proc.state is State.WAITING:
                if proc.blocked_at == CYCLE_WAIT:
                    due.append(proc.next_start)
                elif proc.wake_at is not None:
                    due.append(proc.wake_at)
        return due

    def _idle(self) -> None:
        """Nothing can run: sleep until a cyclic start or timed wait is due, or report the
        deadlock."""
        due = self._due_times() + self.interrupts.due(self, self.host.now())
        if not due:
            raise self._at_main(fail(K.DEADLOCK, "every process waits and nothing can wake them"))
        self.host.sleep(min(due) - self.host.now())

    def _at_main(self, error: StrolicError) -> StrolicError:
        """An exception that is no instruction's: located where the program (process 0) is."""
        frame = self.main.frame
        code = frame.codes[frame.pc] if frame.pc < len(frame.codes) else None
        return self._locate(error, self.main, frame, code)

    def finish(self, proc: Process) -> None:
        """A process's root function returned: wait for its next cycle or end."""
        if self.processes.get(proc.number) is proc:    # not an interrupt detection procedure
            self.changed()
        if proc.period:
            proc.state = State.WAITING
            proc.blocked_at = CYCLE_WAIT
            now = self.host.now()
            while proc.next_start <= now:
                proc.next_start += proc.period
        else:
            proc.state = State.DONE

    def _execute(self, proc: Process, limit: int) -> None:
        """The dispatch loop: up to ``limit`` instructions of ``proc`` (fewer if it waits/ends)."""
        stack = proc.stack
        frame = proc.frame
        codes = frame.codes
        count = 0
        budget = self.budget
        instruction = None
        try:
            while count < limit and proc.state is State.RUNNING:
                pc = frame.pc
                if pc >= len(codes):
                    self.fall_off(proc)
                else:
                    instruction = codes[pc]
                    if budget is not None and self.executed + count >= budget:
                        raise fail(K.INSTRUCTION_BUDGET, f"{budget} instructions executed")
                    frame.pc = pc + 1
                    op = instruction[0]
                    if op == PUSH:
                        stack.append(instruction[1])
                    elif op == BUILTIN:
                        handler = instruction[1].handler
                        if handler is not None:
                            result = handler(self, proc)
                        else:       # a host function may block (PAUSE): the count so far shows
                            self.in_slice = count
                            result = self.host.call(self, proc, instruction[1])
                        if result is WAIT:
                            frame.pc = pc
                            proc.state = State.WAITING
                            proc.blocked_at = self.generation
                            break
                    elif op == USER:
                        self.evaluate_user(proc, instruction[1])
                    else:
                        self.evaluate_user(proc, self.indirect_key(proc, instruction[1]))
                    if len(stack) > self.max_stack:
                        raise fail(K.STACK_OVERFLOW, f"more than {self.max_stack} items")
                    count += 1
                if proc.frame is not frame:
                    frame = proc.frame
                    codes = frame.codes
        except StrolicError as error:
            raise self._locate(error, proc, frame, instruction)
        except Exception as error:      # a fault of the VM itself: the program's exception
            raise self._locate(fail(K.COMPUTER_ERROR, f"{type(error).__name__}: {error}"),
                               proc, frame, instruction) from error
        finally:
            self.executed += count
            self.in_slice = 0
            proc.last_run = self.executed

    def _locate(self, error: StrolicError, proc: Process, frame: Frame,
                instruction) -> StrolicError:
        """Name the failing code and its byte offset in the program (§4.5 report)."""
        if instruction is None:
            return error
        op, argument, offset, _ = instruction
        name = (argument.mnemonic if op == BUILTIN else f"%{argument:04X}" if op == USER
                else f"@%{argument:04X}" if op == INDIRECT else "data")
        if frame.function is not None:
            name += f" (in function {frame.name})"
        if proc.number:
            name += f" ({proc.name})"
        return error.located(name, self.program_offset(proc, frame, offset))

    @staticmethod
    def program_offset(proc: Process, frame: Frame, offset: int) -> int | None:
        """Where the program stands: in a body made at run time (no place in the program), at
        the code that called it."""
        if frame.origin is not None:
            return frame.origin + offset
        for kind, caller in reversed(proc.returns):
            if kind == "call" and caller.origin is not None:
                return caller.origin + caller.codes[caller.pc - 1][2]
        return None

    # ---- interrupt processes (interrupts.py) ----------------------------------------------------
    def handler_running(self, label: str) -> bool:
        proc = self.processes.get(label)
        return proc is not None and proc.state is not State.DONE

    def start_handler(self, label: str, function: Function) -> None:
        """An interrupt's action as a process that goes before every other."""
        proc = Process(label, self.function_frame(function, label),
                       self.scopes_for_new_process())
        proc.priority = INTERRUPT_PRIORITY
        self.processes[label] = proc
        self.changed()

    def detect(self, function: Function, label: str) -> bool:
        """Run an interrupt detection procedure to its end: is its result true?"""
        proc = Process(f"{label} detection", self.function_frame(function, label),
                       self.scopes_for_new_process())
        while proc.state is State.RUNNING:
            self._execute(proc, SLICE)
        if proc.state is not State.DONE:
            raise StrolicError(K.DETECTION_WAITED, "it must end without waiting",
                               function=proc.name, offset=function.origin)
        if not proc.stack or not isinstance(proc.stack[-1], Num):
            raise StrolicError(K.TYPE_MISMATCH, "an interrupt detection procedure must leave "
                               "a logical value", function=proc.name, offset=function.origin)
        return proc.stack[-1].value != 0

    # ---- frames and calls -----------------------------------------------------------------------
    def fall_off(self, proc: Process) -> None:
        """Past the last code: the program ends, or a function body returns like END."""
        if proc.frame is proc.root and proc.frame.function is None:
            proc.state = State.DONE
            self.changed()
        else:
            self.end_function(proc)

    def call(self, proc: Process, function: Function, name: str) -> None:
        if len(proc.returns) >= self.max_return_depth:
            raise fail(K.STACK_OVERFLOW, "return stack overflow")
        proc.returns.append(("call", proc.frame))
        proc.frame = self.function_frame(function, name)

    def end_function(self, proc: Process) -> None:
        """END: leave the function, dropping its BAL links; a process's root function ends it."""
        while proc.returns:
            kind, target = proc.returns.pop()
            if kind == "call":
                proc.frame = target
                return
        if proc.frame.function is not None:
            self.finish(proc)

    def evaluate_user(self, proc: Process, key: int) -> None:
        """A function code runs its body; a variable code pushes its value (§17.2)."""
        value = find(proc.scopes, key).value()
        if isinstance(value, Function):
            self.call(proc, value, f"%{key:04X}")
        else:
            proc.stack.append(value)

    def indirect_key(self, proc: Process, key: int) -> int:
        """F7 u: u holds a suppressed user code (or its code value) to evaluate (§8)."""
        target = find(proc.scopes, key).value()
        if isinstance(target, UserCode):
            return user_key(target.code)
        if isinstance(target, Num):
            return user_key(user_code_of(target))
        raise fail(K.TYPE_MISMATCH, "an indirect reference needs a user code in the variable")

