"""The one place where ROS messages become core values and back.

Core operations take plain Python values (floats, ints, bools, strings, lists, tuples) named like
the request fields; their out values are written into the response fields of the same name.
A nested message is read as the tuple of its fields and written from a tuple (field order) or a dict.
"""
from __future__ import annotations

import functools
import importlib
import operator
from typing import Any, Callable

import numpy as np
from rosidl_parser.definition import AbstractNestedType, NamespacedType


def is_message(value: Any) -> bool:
    return hasattr(type(value), "get_fields_and_field_types")


def to_core(value: Any) -> Any:
    """A value of any field as a core value: messages → tuples of fields, arrays → lists."""
    if is_message(value):
        return _field_values(type(value))(value)
    if isinstance(value, (list, tuple)) or hasattr(value, "tolist"):
        return [to_core(v) for v in (value.tolist() if hasattr(value, "tolist") else value)]
    return value


# element types whose sequences and arrays a message holds as array.array or numpy arrays
_NUMERIC = frozenset({"float", "double", "int8", "uint8", "int16", "uint16",
                      "int32", "uint32", "int64", "uint64"})


def _reader(slot: Any) -> Callable[[Any], Any] | None:
    """`to_core` specialised to one field's type, decided once instead of on every value: None
    for a field read as it is, `tolist` called from C for a numeric array, a nested message's
    `_field_values` (a pose read generically took 24 Python calls for its 12 floats)."""
    if isinstance(slot, NamespacedType):
        return _field_values(_message_class(slot))
    if isinstance(slot, AbstractNestedType):
        inner = slot.value_type
        if isinstance(inner, NamespacedType):
            return functools.partial(_each, _field_values(_message_class(inner)))
        if getattr(inner, "typename", None) in _NUMERIC:
            return operator.methodcaller("tolist")
        return lambda v: v.tolist() if hasattr(v, "tolist") else list(v)
    return None


def _each(read: Callable[[Any], Any], values: Any) -> list:
    return list(map(read, values))


@functools.lru_cache(maxsize=None)
def _field_values(cls: type) -> Callable[[Any], tuple]:
    """The fields of a message of class `cls` in order, each as its core value: the fields and
    their conversions looked up once per type (`_reader`), the fields read in one C call."""
    names = tuple(cls.get_fields_and_field_types())
    if not names:
        return lambda msg: ()
    get = operator.attrgetter(*names)
    converted = tuple((i, read) for i, read in enumerate(map(_reader, cls.SLOT_TYPES))
                      if read is not None)
    if len(names) == 1:
        read = converted[0][1] if converted else None
        return (lambda msg: (get(msg),)) if read is None else (lambda msg: (read(get(msg)),))
    if not converted:
        return get

    def values(msg: Any) -> tuple:
        got = list(get(msg))
        for i, read in converted:
            got[i] = read(got[i])
        return tuple(got)
    return values


def request_reader(request_type: type) -> Callable[[Any], dict[str, Any]]:
    """The core keyword arguments of a request of `request_type` (`_field_values`; a request
    of one field, as most are, without a comprehension: one Python call less per request)."""
    names = tuple(request_type.get_fields_and_field_types())
    values = _field_values(request_type)
    if len(names) == 1:
        (name,) = names
        read = _reader(request_type.SLOT_TYPES[0])
        get = operator.attrgetter(name)
        if read is None:
            return lambda request: {name: get(request)}
        return lambda request: {name: read(get(request))}
    return lambda request: dict(zip(names, values(request)))


@functools.lru_cache(maxsize=None)
def _slots(cls: type) -> dict[str, Any]:
    return dict(zip(cls.get_fields_and_field_types(), cls.SLOT_TYPES))


def _message_class(t: NamespacedType) -> type:
    return getattr(importlib.import_module(".".join(t.namespaces)), t.name)


def _build(cls: type, value: Any) -> Any:
    """A message of class `cls` from a tuple (in field order), a dict, or a message already."""
    if isinstance(value, cls):
        return value
    slots = _slots(cls)
    items = value.items() if isinstance(value, dict) else zip(slots, value)
    msg = cls()
    for name, v in items:
        setattr(msg, name, _convert(slots[name], v))
    return msg


# Messages built from core values, by field type and value: a getter answers the same limits,
# offsets or pose again and again, and building its nested messages was most of its work (a
# setter per field). They are shared read-only: a response is serialised as it is sent.
_BUILT: dict[tuple[int, Any], Any] = {}
_BUILT_MAX = 512


def frozen(value: Any) -> Any:
    """A hashable copy of a core value (lists and arrays → tuples), or None if it has none."""
    if isinstance(value, np.ndarray):
        value = value.tolist()
    if isinstance(value, list):
        value = tuple(value)
    try:
        hash(value)                 # the usual case at once: a tuple of numbers or of tuples
        return value
    except TypeError:
        if not isinstance(value, tuple):
            return None
    items = tuple(frozen(v) for v in value)
    return None if None in items else items


def reply_key(code: Any, comment: str, values: dict[str, Any]) -> tuple | None:
    """A hashable copy of a reply (its values `frozen` one by one), or None if a value has none.
    Value by value, a list is a tuple at once; frozen over the whole reply met an unhashable
    level first at every list (a getter's key took 5 µs instead of 0.8, on a warm core)."""
    items = []
    for name, value in values.items():
        kept = frozen(value)
        if kept is None and value is not None:
            return None
        items.append((name, kept))
    return code, comment, tuple(items)


def _convert(slot: Any, value: Any) -> Any:
    if isinstance(slot, NamespacedType):
        return _cached(slot, value, lambda: _build(_message_class(slot), value))
    if isinstance(slot, AbstractNestedType):
        inner = slot.value_type
        if isinstance(inner, NamespacedType):
            cls = _message_class(inner)
            return _cached(slot, value, lambda: [_build(cls, v) for v in value])
        if isinstance(value, np.ndarray):
            return value.tolist()
        return [v.item() if isinstance(v, np.generic) else v for v in value]
    return value.item() if isinstance(value, np.generic) else value


_LAST: dict[int, tuple[Any, Any]] = {}     # per field type: the last core value and its build
# (a value handed to `fill` is never changed afterwards: cores answer new or immutable values)


def _cached(slot: Any, value: Any, build: Callable[[], Any]) -> Any:
    last = _LAST.get(id(slot))
    if last is not None and last[0] is value:   # a core that memoises answered the same object
        return last[1]
    hashable = frozen(value)
    if hashable is None:
        return build()
    key = (id(slot), hashable)
    built = _BUILT.get(key)
    if built is None:
        if len(_BUILT) >= _BUILT_MAX:
            _BUILT.clear()
        built = _BUILT[key] = build()
    _LAST[id(slot)] = (value, built)
    return built


def fill(msg: Any, values: dict[str, Any]) -> None:
    """Write core out-values into the same-named fields of a message (KeyError if absent)."""
    slots = _slots(type(msg))
    for name, value in values.items():
        setattr(msg, name, _convert(slots[name], value))
