"""The one place where ROS messages become core values and back.

Core operations take plain Python values (floats, ints, bools, strings, lists, tuples) named like
the request fields; their out values are written into the response fields of the same name.
A nested message is read as the tuple of its fields and written from a tuple (field order) or a dict.
"""
from __future__ import annotations

import importlib
from typing import Any

import numpy as np
from rosidl_parser.definition import AbstractNestedType, NamespacedType


def is_message(value: Any) -> bool:
    return hasattr(type(value), "get_fields_and_field_types")


def to_core(value: Any) -> Any:
    """A request field as a core value: messages → tuples of fields, arrays → lists."""
    if is_message(value):
        return tuple(to_core(getattr(value, f)) for f in value.get_fields_and_field_types())
    if isinstance(value, (list, tuple)) or hasattr(value, "tolist"):
        return [to_core(v) for v in (value.tolist() if hasattr(value, "tolist") else value)]
    return value


def _message_class(t: NamespacedType) -> type:
    return getattr(importlib.import_module(".".join(t.namespaces)), t.name)


def _build(cls: type, value: Any) -> Any:
    """A message of class `cls` from a tuple (in field order), a dict, or a message already."""
    if isinstance(value, cls):
        return value
    names = list(cls.get_fields_and_field_types())
    if isinstance(value, dict):
        items = value.items()
    else:
        items = zip(names, value)
    msg = cls()
    for (name, v), slot in zip(items, cls.SLOT_TYPES):
        setattr(msg, name, _convert(slot, v))
    return msg


def _convert(slot: Any, value: Any) -> Any:
    if isinstance(slot, NamespacedType):
        return _build(_message_class(slot), value)
    if isinstance(slot, AbstractNestedType):
        inner = slot.value_type
        if isinstance(inner, NamespacedType):
            cls = _message_class(inner)
            return [_build(cls, v) for v in value]
        return [_scalar(v) for v in value]
    return _scalar(value)


def _scalar(v: Any) -> Any:
    return v.item() if isinstance(v, np.generic) else v


def fill(msg: Any, values: dict[str, Any]) -> None:
    """Write core out-values into the same-named fields of a message (KeyError if absent)."""
    fields = list(msg.get_fields_and_field_types())
    for name, value in values.items():
        slot = msg.SLOT_TYPES[fields.index(name)]
        setattr(msg, name, _convert(slot, value))
