"""ROS parameters from a core's config dataclass: every field becomes a parameter of that name.

Each parameter gets a `ParameterDescriptor`: its description is the field's comment in the
dataclass source (or `metadata["description"]`), its range `metadata["range"]` = (lo, hi) where
the field has one. A parameter is read-only, so `ros2 param set` is refused, unless the node
passes a `Setting` for it: a set then goes through `Setting.apply`, which applies the value with
the validation of the matching service and answers that service's `Reply`; a refusal refuses the
set with the reply's comment as the reason. `sync_parameters` shows settings changed through the
services (or as a side effect of another setting) in the parameters.
"""
from __future__ import annotations

import ast
import dataclasses
import inspect
import io
import math
import textwrap
import tokenize
from dataclasses import dataclass
from functools import lru_cache
from typing import Any, Callable, Mapping, TypeVar

from rcl_interfaces.msg import (FloatingPointRange, IntegerRange, ParameterDescriptor,
                                SetParametersResult)
from rclpy.node import Node
from rclpy.parameter import Parameter

from acti_motion.replies import Reply

C = TypeVar("C")


@dataclass(frozen=True)
class Setting:
    """How a parameter takes effect at run time: `apply(value)` sets it through the matching
    service's validation (its Reply), `read()` gives the value in force (for sync_parameters)."""
    apply: Callable[[Any], Reply]
    read: Callable[[], Any]


def widened(p: Parameter, declared_type: int) -> Parameter:
    """An integer given for a double (or integers for a double array) as the double(s) it means,
    instead of a type error: `-p rate_hz:=250` and `ros2 param set … 250` mean 250.0."""
    if declared_type == Parameter.Type.DOUBLE.value and p.type_ == Parameter.Type.INTEGER:
        return Parameter(p.name, Parameter.Type.DOUBLE, float(p.value))
    if declared_type == Parameter.Type.DOUBLE_ARRAY.value \
            and p.type_ == Parameter.Type.INTEGER_ARRAY:
        return Parameter(p.name, Parameter.Type.DOUBLE_ARRAY, [float(x) for x in p.value])
    return p


def _check_finite(name: str, value: Any) -> None:
    """ValueError unless every number of a double (or double array) parameter is finite: no
    setting of these nodes means anything at NaN or infinity, and comparisons let NaN through
    (`rate_hz <= 0` is false for NaN)."""
    numbers = value if isinstance(value, (list, tuple)) else [value]
    bad = [x for x in numbers if isinstance(x, float) and not math.isfinite(x)]
    if bad:
        raise ValueError(f"{name} = {value if isinstance(value, float) else list(value)}: "
                         "it must be finite")


def _start_up_value(node: Node, name: str, declared: Any) -> tuple[Any, bool]:
    """(value, True) when the start-up override of `name` (`--ros-args -p name:=…`, which rclpy
    keeps in `_parameter_overrides`) is an integer for a double, as the double; else
    (declared, False): rclpy applies the override itself."""
    override = getattr(node, "_parameter_overrides", {}).get(name)
    if override is None:
        return declared, False
    want = Parameter.Type.from_parameter_value(declared).value
    wide = widened(override, want)
    return (wide.value, True) if wide is not override else (declared, False)


class _Parameters:
    """The settable parameters of one node and the callbacks that serve them."""

    def __init__(self, node: Node) -> None:
        self.node = node
        self.settings: dict[str, Setting] = {}
        node.add_pre_set_parameters_callback(self._widen_integers)
        node.add_on_set_parameters_callback(self._apply)

    def _widen_integers(self, parameters: list[Parameter]) -> list[Parameter]:
        """`ros2 param set … max_speed_translation 250` means 250.0 (see `widened`)."""
        return [widened(p, self.node.describe_parameter(p.name).type)
                if self.node.has_parameter(p.name) else p for p in parameters]

    def _apply(self, parameters: list[Parameter]) -> SetParametersResult:
        """Apply each value through its setting; if one is refused, put back what the others
        changed (an atomic set changes nothing or everything: a refused one left the values
        before the bad one applied)."""
        before = {name: _as_parameter_value(s.read()) for name, s in self.settings.items()}
        for p in parameters:
            setting = self.settings.get(p.name)
            if setting is None or not self.node.has_parameter(p.name):
                continue          # a declaration, or refused as read-only before this
            if _as_parameter_value(p.value) == _as_parameter_value(setting.read()):
                continue          # in force already (also: sync showing a service's change)
            value = tuple(p.value) if isinstance(p.value, (list, tuple)) else p.value
            reply = setting.apply(value)
            if not reply.ok:
                self._restore(before)
                return SetParametersResult(successful=False, reason=reply.comment)
        return SetParametersResult(successful=True)

    def _restore(self, before: dict[str, Any]) -> None:
        """Every setting back to its value in `before`; a second pass for settings that bound
        each other (a minimum and the value above it), which only one order accepts."""
        for _ in range(2):
            for name, value in reversed(before.items()):
                setting = self.settings[name]
                if _as_parameter_value(setting.read()) != value:
                    setting.apply(tuple(value) if isinstance(value, list) else value)

    def sync(self) -> None:
        """Set every settable parameter whose value differs from the one in force."""
        changed = []
        for name, setting in self.settings.items():
            now = _as_parameter_value(setting.read())
            if _as_parameter_value(self.node.get_parameter(name).value) != now:
                changed.append(Parameter(name, value=now))
        if changed:
            self.node.set_parameters(changed)


def declare_config(node: Node, config_type: type[C],
                   settings: Mapping[str, Setting] | None = None) -> C:
    """Declare one parameter per field (default = the field's default, descriptor from the
    field's comment and metadata) and build the config. Fields named in `settings` can be set
    at run time; all others are read-only."""
    settings = dict(settings or {})
    fields = dataclasses.fields(config_type)
    unknown = set(settings) - {f.name for f in fields}
    if unknown:
        raise ValueError(f"{config_type.__name__} has no field {', '.join(sorted(unknown))}")
    notes = field_descriptions(config_type)
    defaults = config_type()
    values: dict[str, Any] = {}
    for f in fields:
        default = getattr(defaults, f.name)
        declared = _as_parameter_value(default)
        descriptor = _descriptor(f, declared, notes.get(f.name, ""), f.name in settings)
        start, own = _start_up_value(node, f.name, declared)
        value = node.declare_parameter(f.name, start, descriptor, ignore_override=own).value
        _defaults_of(node)[f.name] = declared
        _check_finite(f.name, value)
        values[f.name] = tuple(value) if isinstance(default, tuple) else value
    if settings:
        _parameters_of(node).settings.update(settings)
    return config_type(**values)


def sync_parameters(node: Node) -> None:
    """Show in the parameters the settings in force (changed through a service, or raised by
    another setting); a node without settable parameters has nothing to do."""
    registry = getattr(node, "_acti_parameters", None)
    if registry is not None:
        registry.sync()


def _defaults_of(node: Node) -> dict[str, Any]:
    """The declared default of each parameter (what `--help` lists; -p may have set another)."""
    if not hasattr(node, "_acti_defaults"):
        setattr(node, "_acti_defaults", {})
    return getattr(node, "_acti_defaults")


def _parameters_of(node: Node) -> _Parameters:
    registry = getattr(node, "_acti_parameters", None)
    if registry is None:
        registry = _Parameters(node)
        setattr(node, "_acti_parameters", registry)
    return registry


def _as_parameter_value(value: Any) -> Any:
    """A value as a parameter holds it: sequences as lists (numpy numbers as Python ones)."""
    if isinstance(value, (tuple, list)) or hasattr(value, "tolist"):
        return [x.item() if hasattr(x, "item") else x for x in value]
    return value


def _descriptor(f: dataclasses.Field, value: Any, note: str, settable: bool) -> ParameterDescriptor:
    description = f.metadata.get("description", note)
    if not settable:
        description += " (read-only: set at start-up)"
    d = ParameterDescriptor(name=f.name, description=description.strip(), read_only=not settable)
    lo, hi = f.metadata.get("range", (None, None))
    if isinstance(value, float) and lo is not None:
        d.floating_point_range = [FloatingPointRange(from_value=float(lo), to_value=float(hi),
                                                     step=0.0)]
    elif isinstance(value, int) and not isinstance(value, bool) and lo is not None:
        d.integer_range = [IntegerRange(from_value=int(lo), to_value=int(hi), step=0)]
    return d


@lru_cache(maxsize=None)
def field_descriptions(config_type: type) -> dict[str, str]:
    """The comment of every field in the dataclass source: on the field's own lines, or else
    the comment lines right above it."""
    try:
        source = textwrap.dedent(inspect.getsource(config_type))
    except (OSError, TypeError):
        return {}
    comments: dict[int, str] = {}          # line → comment
    alone: set[int] = set()                 # lines that hold only a comment
    for tok in tokenize.generate_tokens(io.StringIO(source).readline):
        if tok.type == tokenize.COMMENT:
            comments[tok.start[0]] = tok.string.lstrip("#").strip()
            if tok.line.lstrip().startswith("#"):
                alone.add(tok.start[0])
    out: dict[str, str] = {}
    cls = ast.parse(source).body[0]
    for node in getattr(cls, "body", []):
        if not (isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name)):
            continue
        own = [comments[n] for n in range(node.lineno, node.end_lineno + 1) if n in comments]
        above, n = [], node.lineno - 1
        while n in alone and not own:
            above.insert(0, comments[n])
            n -= 1
        out[node.target.id] = " ".join(own or above)
    return out
