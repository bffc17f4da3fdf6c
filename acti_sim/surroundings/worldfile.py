"""The world file: static obstacles on the floor, in YAML, SI units and REP 103 frames.

    name: room                      # optional
    boxes:
      - name: north_wall            # optional
        size: [6.0, 0.1, 1.0]       # x, y, z [m]
        pose: [0.0, 3.0, 0.0]       # x, y [m], yaw [rad] of the centre, in the world (= map) frame
    cylinders:
      - radius: 0.15                # [m]
        height: 1.0                 # [m]
        pose: [1.5, -1.0, 0.0]

Every obstacle stands on the floor (z = 0 up to its height). The robot starts at the origin
facing +x. A file that breaks a rule is refused whole with `WorldFileError`: the file, the entry
and what is wrong.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import yaml

if TYPE_CHECKING:
    from acti_sim.world import World

# the largest size or coordinate a world file may give [m]: a building, not a planet
MAX_EXTENT_M = 1000.0
TOP_LEVEL = ("name", "boxes", "cylinders")
BOX_KEYS = {"name": False, "size": True, "pose": True}
CYLINDER_KEYS = {"name": False, "radius": True, "height": True, "pose": True}


class WorldFileError(ValueError):
    """A world file that cannot be used: says which file, which entry and what is wrong."""

    def __init__(self, path: str, entry: str, what: str) -> None:
        super().__init__(f"world file {path}: {entry}: {what}")
        self.path, self.entry, self.what = path, entry, what


@dataclass(frozen=True)
class Box:
    name: str
    size: tuple[float, float, float]      # x, y, z [m]
    pose: tuple[float, float, float]      # x, y [m], yaw [rad]


@dataclass(frozen=True)
class Cylinder:
    name: str
    radius: float                         # [m]
    height: float                         # [m]
    pose: tuple[float, float, float]      # x, y [m], yaw [rad] (a cylinder's yaw changes nothing)


@dataclass(frozen=True)
class WorldSpec:
    name: str = ""
    boxes: tuple[Box, ...] = ()
    cylinders: tuple[Cylinder, ...] = ()

    def bounds(self) -> tuple[float, float, float, float] | None:
        """(x min, y min, x max, y max) of every obstacle's footprint [m]; None when empty."""
        corners = []
        for b in self.boxes:
            x, y, yaw = b.pose
            c, s = math.cos(yaw), math.sin(yaw)
            hx, hy = b.size[0] / 2, b.size[1] / 2
            ex, ey = abs(c) * hx + abs(s) * hy, abs(s) * hx + abs(c) * hy
            corners += [(x - ex, y - ey), (x + ex, y + ey)]
        for cyl in self.cylinders:
            x, y, _ = cyl.pose
            corners += [(x - cyl.radius, y - cyl.radius), (x + cyl.radius, y + cyl.radius)]
        if not corners:
            return None
        xs, ys = [p[0] for p in corners], [p[1] for p in corners]
        return min(xs), min(ys), max(xs), max(ys)


def load_world(path: str) -> WorldSpec:
    """Read and check a world file (`WorldFileError` if it cannot be used)."""
    try:
        with open(path) as f:
            data = yaml.safe_load(f)
    except OSError as e:
        raise WorldFileError(path, "the file", e.strerror or str(e)) from None
    except yaml.YAMLError as e:
        raise WorldFileError(path, "the file", f"not YAML: {e}".replace("\n", " ")) from None
    return parse_world(data, path)


def parse_world(data: Any, path: str = "<world>") -> WorldSpec:
    """A WorldSpec from the YAML's data (None, an empty file, is an empty world)."""
    if data is None:
        return WorldSpec()
    if not isinstance(data, dict):
        raise WorldFileError(path, "the file", f"a mapping of {', '.join(TOP_LEVEL)} is needed, "
                                               f"not {type(data).__name__}")
    unknown = [str(k) for k in data if k not in TOP_LEVEL]
    if unknown:
        raise WorldFileError(path, "the file", f"unknown key {', '.join(unknown)} (known: "
                                               f"{', '.join(TOP_LEVEL)})")
    name = data.get("name", "")
    if not isinstance(name, str):
        raise WorldFileError(path, "name", f"{name!r} is not a string")
    boxes = tuple(_box(e, _Entry(path, "boxes", i, e)) for i, e in enumerate(_list(data, "boxes", path)))
    cylinders = tuple(_cylinder(e, _Entry(path, "cylinders", i, e))
                      for i, e in enumerate(_list(data, "cylinders", path)))
    return WorldSpec(name, boxes, cylinders)


def _list(data: dict, key: str, path: str) -> list:
    value = data.get(key) or []
    if not isinstance(value, list):
        raise WorldFileError(path, key, f"a list of entries is needed, not {type(value).__name__}")
    return value


class _Entry:
    """One entry of a list, for its checks and for naming it in an error."""

    def __init__(self, path: str, kind: str, index: int, data: Any) -> None:
        name = data.get("name") if isinstance(data, dict) else None
        self.path = path
        self.label = f"{kind}[{index}]" + (f" ({name!r})" if isinstance(name, str) and name else "")
        self.data = data

    def fail(self, what: str) -> WorldFileError:
        return WorldFileError(self.path, self.label, what)

    def check_keys(self, keys: dict[str, bool]) -> None:
        if not isinstance(self.data, dict):
            raise self.fail(f"a mapping of {', '.join(keys)} is needed, not {self.data!r}")
        unknown = [str(k) for k in self.data if k not in keys]
        if unknown:
            raise self.fail(f"unknown key {', '.join(unknown)} (known: {', '.join(keys)})")
        missing = [k for k, required in keys.items() if required and k not in self.data]
        if missing:
            raise self.fail(f"{', '.join(missing)} missing")
        if not isinstance(self.data.get("name", ""), str):
            raise self.fail(f"name {self.data['name']!r} is not a string")

    def numbers(self, key: str, count: int, positive: bool) -> tuple[float, ...]:
        value = self.data[key]
        values = value if isinstance(value, list) else [value]
        if len(values) != count or not all(_is_number(v) for v in values):
            shape = "a number" if count == 1 else f"a list of {count} numbers"
            raise self.fail(f"{key} is {value!r}: {shape} is needed")
        out = tuple(float(v) for v in values)
        if not all(math.isfinite(v) and abs(v) <= MAX_EXTENT_M for v in out):
            raise self.fail(f"{key} is {value!r}: every number must be finite and within "
                            f"±{MAX_EXTENT_M:g} m")
        if positive and not all(v > 0 for v in out):
            raise self.fail(f"{key} is {value!r}: sizes must be > 0 m")
        return out

    def pose(self) -> tuple[float, float, float]:
        x, y, yaw = self.numbers("pose", 3, positive=False)
        return x, y, yaw


def _is_number(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def _box(data: Any, entry: _Entry) -> Box:
    entry.check_keys(BOX_KEYS)
    sx, sy, sz = entry.numbers("size", 3, positive=True)
    return Box(data.get("name", ""), (sx, sy, sz), entry.pose())


def _cylinder(data: Any, entry: _Entry) -> Cylinder:
    entry.check_keys(CYLINDER_KEYS)
    (radius,) = entry.numbers("radius", 1, positive=True)
    (height,) = entry.numbers("height", 1, positive=True)
    return Cylinder(data.get("name", ""), radius, height, entry.pose())


def build_world(world: "World", spec: WorldSpec) -> None:
    """Put the obstacles of `spec` into the PyBullet world, standing on its floor."""
    for b in spec.boxes:
        x, y, yaw = b.pose
        world.add_box((x, y, b.size[2] / 2), (b.size[0] / 2, b.size[1] / 2, b.size[2] / 2), yaw=yaw)
    for c in spec.cylinders:
        x, y, _ = c.pose
        world.add_cylinder((x, y, c.height / 2), c.radius, c.height)
