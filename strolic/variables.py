"""The variable table of Reference 1: user codes → heap areas, in nested scopes (§5, §6, §8).

A binding holds a value and, once bytes are addressed (ALLOC, EXTB, EMBB …), its *area*: the
data part as a bytearray under a head. The value is rebuilt from the area after a write, so
structured data stays a plain immutable value everywhere else.
"""
from __future__ import annotations

from .codes import ARRAY, DATA_TYPES, LENGTH_TAGS, TagHead, type_name
from .errors import ExceptionKind as K, fail
from .values import data_of, encode_item, head_of, value_from_data


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
        """ALLOC: an area of ``size`` data bytes under ``head`` (lengths set to ``size``)."""
        if head.tag in LENGTH_TAGS or head.tag == ARRAY:
            head = TagHead(head.tag, size, head.element)
            element_size = head.element.element_size() if head.tag == ARRAY else 0
            if element_size and size % element_size:
                raise fail(K.TYPE_MISMATCH, "area size is not a multiple of the element size")
        elif size < head.element_size():
            raise fail(K.AREA_ERROR, f"{size} bytes cannot hold {type_name(head)} data")
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
        if self.area is not None:
            return len(self.area)
        if self._value is None:
            return None
        if isinstance(self._value, DATA_TYPES):
            return len(data_of(self._value))
        return len(encode_item(self._value))

    def release(self) -> None:
        self._value, self.head, self.area = None, None, None


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
