"""The variable table of Reference 1: user codes → heap areas, in nested scopes (§5, §6, §8).

A binding holds a value and, once bytes are addressed (ALLOC, EXTB, EMBB …), its *area*: the
tag (``head``) and the data part as a bytearray. The value is rebuilt from the area after a
write, so structured data stays a plain immutable value everywhere else. The size of an area is
that of the tagged datum, tag included (EF67: ALLOC secures a plus the length of the tag and
writes the tag into it); a value without an area counts as the tagged datum it would fill.
"""
from __future__ import annotations

from .codes import ARRAY, LENGTH_TAGS, TagHead, type_name
from .errors import ExceptionKind as K, fail
from .values import data_of, encode_head, encode_item, head_of, value_from_data


class Binding:
    """One registration of a user code; no value and no area right after DCL."""

    __slots__ = ("_value", "head", "area")

    def __init__(self) -> None:
        self._value = None
        self.head: TagHead | None = None
        self.area: bytearray | None = None

    @property
    def defined(self) -> bool:
        return self._value is not None or self.area is not None

    def value(self):
        if self._value is None:
            if self.area is None:
                raise fail(K.UNDEFINED_DATA, "the user code has no value")
            size = self.head.element_size()
            self._value = value_from_data(self.head, bytes(self.area[:size]))
        return self._value

    def assign(self, value) -> None:
        """STORE/POP: the old area is released, the value gets its own (Reference 1 §6).
        Any stack item can be assigned, a suppressed user code too (for indirect references)."""
        self._value, self.head, self.area = value, None, None

    def allocate(self, head: TagHead, size: int) -> None:
        """ALLOC: a zeroed area of ``size`` data bytes under ``head`` (an ``area_head``)."""
        self._value, self.head, self.area = None, head, bytearray(size)

    def bytes_area(self) -> bytearray:
        """The area, materialised from the value on first byte access."""
        if self.area is None:
            if self._value is None:
                raise fail(K.AREA_ERROR, "no area is allocated to the user code")
            self.head, self.area = head_of(self._value), bytearray(data_of(self._value))
        return self.area

    def written(self) -> None:
        """The area changed: the cached value is stale."""
        self._value = None

    def size(self) -> int | None:
        """Bytes of the area, tag included (ASIZE, the heap); None without a value."""
        if self.area is not None:
            return len(encode_head(self.head)) + len(self.area)
        if self._value is None:
            return None
        return len(encode_item(self._value))

    def release(self) -> None:
        self._value, self.head, self.area = None, None, None


def area_head(head: TagHead, size: int) -> TagHead:
    """ALLOC's tag for ``size`` data bytes: lengths are set to ``size`` (an array needs a
    multiple of its element size); a fixed type needs at least its size."""
    if head.tag in LENGTH_TAGS or head.tag == ARRAY:
        element_size = head.element.element_size() if head.tag == ARRAY else 0
        if element_size and size % element_size:
            raise fail(K.TYPE_MISMATCH, "area size is not a multiple of the element size")
        return TagHead(head.tag, size, head.element)
    if size < head.element_size():
        raise fail(K.AREA_ERROR, f"{size} bytes cannot hold {type_name(head)} data")
    return head


def area_size(head: TagHead, size: int) -> int:
    """EF67: the area ALLOC secures is ``size`` plus the length of the tag written into it."""
    return len(encode_head(head)) + size


class Scope:
    """A local variable space of one nesting level; each code keeps a stack of registrations."""

    __slots__ = ("level", "table")

    def __init__(self, level: int) -> None:
        self.level = level
        self.table: dict[int, list[Binding]] = {}


def visible_scopes(scopes: list[Scope]):
    """Innermost first; an outer scope whose level is not below every inner one is hidden (§8)."""
    limit = None
    for scope in reversed(scopes):
        if limit is None or scope.level < limit:
            yield scope
            limit = scope.level


def find(scopes: list[Scope], key: int) -> Binding:
    for scope in visible_scopes(scopes):
        registrations = scope.table.get(key)
        if registrations:
            return registrations[-1]
    raise fail(K.UNDEFINED_DATA, f"user code %{key:04X} is not declared")


def find_at_level(scopes: list[Scope], key: int, level: int) -> Binding:
    """NPUSH/NPOP: the innermost scope with that level."""
    for scope in reversed(scopes):
        if scope.level == level:
            registrations = scope.table.get(key)
            if not registrations:
                raise fail(K.UNDEFINED_DATA,
                           f"user code %{key:04X} is not declared at level {level}")
            return registrations[-1]
    raise fail(K.UNDEFINED_DATA, f"nesting level {level} is not defined")


def declare(scope: Scope, key: int) -> None:
    scope.table.setdefault(key, []).append(Binding())


def free(scopes: list[Scope], key: int) -> None:
    """FREE: drop the registration a lookup would find; an unknown code is ignored."""
    for scope in visible_scopes(scopes):
        registrations = scope.table.get(key)
        if registrations:
            registrations.pop()
            if not registrations:
                del scope.table[key]
            return
