"""EF58–EF66 and EF5D–EF63: branches, calls, returns, nesting, declaration of variables.

Branch offsets count bytes from the end of the branch code (0 = the next code) and may be
negative. Outside a function the branch codes pop their operands and do nothing (recommended).
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from ..codes import VAR_CODE, Function, FunctionCode, UserCode, user_key
from ..errors import ExceptionKind as K, fail
from ..process import PUSH, Process
from ..values import ENTRY_BYTES
from ..variables import Scope, declare, find, find_at_level, free as free_binding
from .args import expect, pop_count, pop_num, pop_user

if TYPE_CHECKING:
    from ..vm import VM


def _branch_if(proc: Process, taken: bool, offset: int) -> None:
    frame = proc.frame
    if taken and frame.function is not None:
        frame.jump(offset, frame.pc - 1)


def bra(vm: VM, proc: Process) -> None:
    _branch_if(proc, True, pop_count(proc))


def brf(vm: VM, proc: Process) -> None:
    """BRF: branch when the condition is 0 (a logical test: any type, 0 is false)."""
    offset = pop_count(proc)
    _branch_if(proc, pop_num(proc).value == 0, offset)


def brt(vm: VM, proc: Process) -> None:
    """BRT: branch when the condition is true, i.e. not 0 (Annex 1 §7)."""
    offset = pop_count(proc)
    _branch_if(proc, pop_num(proc).value != 0, offset)


def bal(vm: VM, proc: Process) -> None:
    """BAL: push the position after BAL on the return stack and branch."""
    offset = pop_count(proc)
    frame = proc.frame
    if frame.function is None:
        return
    if len(proc.returns) >= vm.max_return_depth:
        raise fail(K.STACK_OVERFLOW, "return stack overflow")
    proc.returns.append(("bal", frame.pc))
    frame.jump(offset, frame.pc - 1)


def ret(vm: VM, proc: Process) -> None:
    """RET: back to the last BAL or to the caller; the root function of a process ends it."""
    if proc.returns:
        kind, target = proc.returns.pop()
        if kind == "bal":
            proc.frame.pc = target
        else:
            proc.frame = target
    elif proc.frame.function is not None:
        vm.finish(proc)
    else:
        raise fail(K.NO_RETURN_DESTINATION, "RET with nothing to return to")


def end(vm: VM, proc: Process) -> None:
    """END: end of the function body, a return; outside a function it does nothing."""
    vm.end_function(proc)


def gret(vm: VM, proc: Process) -> None:
    """GRET: clear the return stack and go back to the input stream (a process ends)."""
    if proc.frame.function is None:
        return
    proc.returns.clear()
    if proc.root.function is None:
        proc.frame = proc.root
    else:
        vm.finish(proc)


def fdef(vm: VM, proc: Process) -> None:
    """FDEF: the function data after FDEF goes into the user code without the stack."""
    target = pop_user(proc)
    frame = proc.frame
    following = frame.codes[frame.pc][1] if frame.pc < len(frame.codes) else None
    if frame.pc >= len(frame.codes) or frame.codes[frame.pc][0] != PUSH \
            or not isinstance(following, Function):
        raise fail(K.TYPE_MISMATCH, "FDEF must be followed by function data")
    frame.pc += 1
    find(proc.scopes, user_key(target.code)).assign(following)


# ---- nesting (Reference 1 §8) -------------------------------------------------------------------
def nestin(vm: VM, proc: Process) -> None:
    level = pop_count(proc)
    if level < 0:
        raise fail(K.UNDEFINED_DATA, f"negative nesting level {level}")
    if len(proc.scopes) > vm.max_nesting:
        raise fail(K.STACK_OVERFLOW, f"more than {vm.max_nesting} nesting structures")
    proc.scopes.append(Scope(level))


def nestout(vm: VM, proc: Process) -> None:
    """NESTOUT: drop the innermost local space. At the outermost level there is none to leave
    (EF5E leaves NESTOUT without a saved level unspecified): an exception, and the program's
    globals stay as they were, so a handler or the report still sees them."""
    if len(proc.scopes) == 1:
        raise fail(K.COMPUTER_ERROR, "NESTOUT at the outermost level: no nesting structure "
                   "(NESTIN) to leave")
    proc.scopes.pop()


def npush(vm: VM, proc: Process) -> None:
    level = pop_count(proc)
    target = pop_user(proc)
    proc.push(find_at_level(proc.scopes, user_key(target.code), level).value())


def npop(vm: VM, proc: Process) -> None:
    level = pop_count(proc)
    target = pop_user(proc)
    find_at_level(proc.scopes, user_key(target.code), level).assign(proc.pop())


# ---- declaration (Reference 1 §5) ---------------------------------------------------------------
def var(vm: VM, proc: Process) -> None:
    proc.push(FunctionCode(VAR_CODE))


def _declared_codes(proc: Process) -> list[int]:
    """The user codes down to the VAR marker, which is removed too."""
    keys = []
    while True:
        item = proc.pop()
        if item == FunctionCode(VAR_CODE):
            return keys
        keys.append(user_key(expect(item, UserCode, "a suppressed user code (#u) or VAR").code))


def dcl(vm: VM, proc: Process) -> None:
    keys = _declared_codes(proc)
    if len(set(keys)) != len(keys):
        raise fail(K.TYPE_MISMATCH, "a user code appears twice in one declaration")
    vm.account(ENTRY_BYTES * len(keys))
    for key in reversed(keys):
        declare(proc.scopes[-1], key)


def free(vm: VM, proc: Process) -> None:
    for key in _declared_codes(proc):
        free_binding(proc.scopes, key)
