"""EF4A–EF57, EF67–EF6B: stack operations, assignment, bytes and elements of structured data,
arrays, user codes and heap areas.

Offsets of EXTB/EMBB count from 0 at the first byte of the data part (Reference 1 §7) and must
stay inside the data part of the area of the user code (which ALLOC may make larger than the
value); the tag at the start of the area is not addressed.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from ..codes import (ARRAY, DATA_TYPES, I1, I2, I4, INDIRECT, INT_RANGE, NUMERIC_TAGS, R4,
                     STRING, SUPPRESS, TRANSFORM, VECTOR, Array, Num, TagHead, UserCode,
                     make_number, round_half_away, smallest_int, type_name, user_code_of,
                     user_key, wrap_int)
from ..errors import ExceptionKind as K, fail
from ..process import Process
from ..values import array_elements, data_of, head_of, value_from_data
from ..variables import area_head, area_size, find
from .args import (expect, integer_value, pop_count, pop_head, pop_many, pop_num, pop_of,
                   pop_user)

if TYPE_CHECKING:
    from ..vm import VM


# ---- stack operations ---------------------------------------------------------------------------
def dup(vm: VM, proc: Process) -> None:
    proc.push(proc.peek())


def drop(vm: VM, proc: Process) -> None:
    """DROP: an empty stack is not an error."""
    if proc.stack:
        proc.stack.pop()


def exch(vm: VM, proc: Process) -> None:
    """EXCH: fewer than two items is a no-op."""
    stack = proc.stack
    if len(stack) >= 2:
        stack[-1], stack[-2] = stack[-2], stack[-1]


def binding_of(proc: Process, target: UserCode):
    return find(proc.scopes, user_key(target.code))


def push(vm: VM, proc: Process) -> None:
    """PUSH: the value of the user code, a function as data (not executed)."""
    proc.push(binding_of(proc, pop_user(proc)).value())


def pop(vm: VM, proc: Process) -> None:
    target = pop_user(proc)
    binding_of(proc, target).assign(proc.pop())


def store(vm: VM, proc: Process) -> None:
    value = proc.pop()
    binding_of(proc, pop_user(proc)).assign(value)


# ---- bytes of structured data -------------------------------------------------------------------
def _area_slice(binding, start: int, size: int) -> bytearray:
    area = binding.bytes_area()
    if start < 0:
        raise fail(K.AREA_ERROR, f"negative offset {start}")
    if start + size > len(area):
        raise fail(K.AREA_ERROR, f"bytes {start}..{start + size} outside the area of {len(area)}")
    return area


def written(vm: VM, binding, area: bytearray) -> None:
    """After a write the next read makes a new value of the area's size (memory_limit)."""
    vm.claim(len(area))
    binding.written()


def extb(vm: VM, proc: Process) -> None:
    """EXTB #a b #c: the bytes for type c at offset b, tagged c."""
    head = pop_head(proc)
    start = pop_count(proc)
    binding = binding_of(proc, pop_user(proc))
    size = head.element_size()
    area = _area_slice(binding, start, size)
    proc.push(value_from_data(head, bytes(area[start:start + size])))


def embb(vm: VM, proc: Process) -> None:
    """EMBB #a b c: the data part of c (no tag, no length) written at offset b."""
    data = data_of(proc.pop())
    start = pop_count(proc)
    binding = binding_of(proc, pop_user(proc))
    area = _area_slice(binding, start, len(data))
    area[start:start + len(data)] = data
    written(vm, binding, area)


# ---- elements -----------------------------------------------------------------------------------
def _element_layout(binding) -> tuple[TagHead, int, bool]:
    """Element head, element size and 'is an array' of an Ar, St, Vec or Trn value."""
    head = binding.head if binding.area is not None else head_of(binding.value())
    if head.tag == ARRAY:
        return head.element, head.element.element_size(), True
    if head.tag == STRING:
        return TagHead(I1), 1, False
    if head.tag in (VECTOR, TRANSFORM):
        return TagHead(R4), 4, False
    raise fail(K.TYPE_MISMATCH,
               f"EXTE/EMBE need Ar, St, Vec or Trn, not {type_name(binding.value())}")


def exte(vm: VM, proc: Process) -> None:
    index = pop_count(proc)
    binding = binding_of(proc, pop_user(proc))
    element, size, _ = _element_layout(binding)
    area = _area_slice(binding, index * size, size)
    proc.push(value_from_data(element, bytes(area[index * size:index * size + size])))


def embe(vm: VM, proc: Process) -> None:
    """EMBE: arrays take the same type only; strings a number rounded to a byte; Vec/Trn → R4."""
    value = proc.pop()
    index = pop_count(proc)
    binding = binding_of(proc, pop_user(proc))
    element, size, is_array = _element_layout(binding)
    if is_array:
        if head_of(value) != element:
            raise fail(K.TYPE_MISMATCH, f"element type is not {type_name(value)}")
        data = data_of(value)
    elif element.tag == R4:
        data = data_of(make_number(R4, float(numeric(value).value)))
    else:
        data = data_of(wrap_int(I1, integer_value(numeric(value))))
    area = _area_slice(binding, index * size, size)
    area[index * size:index * size + size] = data
    written(vm, binding, area)


def numeric(value) -> Num:
    return expect(value, Num, "a number")


# ---- arrays -------------------------------------------------------------------------------------
def convert_element(value, head: TagHead):
    """CONSA's conversion of an element to the element type, or the §9 type mismatch."""
    if head.tag in NUMERIC_TAGS and isinstance(value, Num):
        number = value.value
        if head.tag <= I4 and not value.is_integer:
            number = round_half_away(number)
        low, high = INT_RANGE.get(head.tag, (None, None))
        if low is not None and not low <= number <= high:
            raise fail(K.TYPE_MISMATCH, f"{number} cannot be converted to the element type")
        return make_number(head.tag, number)
    if isinstance(value, DATA_TYPES) and head_of(value) == head:
        return value
    raise fail(K.TYPE_MISMATCH, f"{type_name(value)} cannot become the element type")


def consa(vm: VM, proc: Process) -> None:
    head = pop_head(proc)
    count = pop_count(proc)
    if head.tag in (SUPPRESS, INDIRECT):
        raise fail(K.TYPE_MISMATCH, "array elements must be data")
    elements = [data_of(convert_element(e, head)) for e in pop_many(proc, count)]
    vm.claim(sum(map(len, elements)))
    proc.push(Array(head, b"".join(elements)))


def desta(vm: VM, proc: Process) -> None:
    """DESTA: the elements from the smallest subscript, then their count (smallest integer type)."""
    array = pop_of(proc, Array, "an array")
    count = len(array.data) // (array.element.element_size() or 1)
    if len(proc.stack) + count + 1 > vm.max_stack:      # checked before millions are made
        raise fail(K.STACK_OVERFLOW, f"{count} elements do not fit the data stack")
    elements = array_elements(array)
    proc.stack.extend(elements)
    proc.push(smallest_int(len(elements)))


# ---- user codes ---------------------------------------------------------------------------------
def consu(vm: VM, proc: Process) -> None:
    proc.push(UserCode(user_code_of(pop_num(proc))))


def destu(vm: VM, proc: Process) -> None:
    """DESTU: the code as I2 bit pattern (2-byte codes) or I4 bit pattern (extended codes)."""
    code = pop_user(proc).code
    proc.push(wrap_int(I2, code) if code <= 0xFFFF else wrap_int(I4, code))


# ---- heap areas ---------------------------------------------------------------------------------
def alloc(vm: VM, proc: Process) -> None:
    """ALLOC and ALLOCZ a #b #c (EF67, EF68): an area of a bytes plus the tag b, which is
    written into it, for c; d is the size of the area (tag included). a ≤ 0 asks the largest
    size that could be secured; a shortfall is returned negative (nothing secured). Every area
    starts zeroed (the Null code is 0x00), so the two functions are one."""
    target = pop_user(proc)
    head = pop_head(proc)
    size = pop_count(proc)
    binding = binding_of(proc, target)
    free_bytes = vm.heap_limit - vm.heap_in_use()
    if size <= 0:
        proc.push(smallest_int(free_bytes))
        return
    if head.tag in (SUPPRESS, INDIRECT):
        raise fail(K.TYPE_MISMATCH, "cannot allocate an area for this tag")
    head = area_head(head, size)
    needed = area_size(head, size)
    if needed > free_bytes:
        proc.push(smallest_int(free_bytes - needed))
    else:
        binding.allocate(head, size)
        proc.push(smallest_int(needed))


def aclr(vm: VM, proc: Process) -> None:
    """ACLR: the data part of the area becomes Null codes; its tag stays."""
    binding = binding_of(proc, pop_user(proc))
    if binding.defined:
        area = binding.bytes_area()
        area[:] = bytes(len(area))
        written(vm, binding, area)


def arels(vm: VM, proc: Process) -> None:
    binding_of(proc, pop_user(proc)).release()


def asize(vm: VM, proc: Process) -> None:
    """ASIZE: bytes of the area, tag included as ALLOC counts them (I2, or I4 when larger),
    −1 when there is none."""
    size = binding_of(proc, pop_user(proc)).size()
    proc.push(Num(I2, -1) if size is None else make_number(I2 if size <= 0x7FFF else I4, size))
