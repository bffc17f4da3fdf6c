"""Taught data: named poses, joint positions and vectors in a file of their own, so that a
program's code and its points change apart. One point a line, ' starts a comment:

    POSE   PICK  = 400, -150, 200, 180, 0, 180     ' x y z (mm), rx ry rz (deg) [, config [, elbow]]
    JOINT  READY = 0, 40, 0, 90, 0, 50, 0          ' J1 … J7 (deg)
    VECTOR LIFT  = 0, 0, 100                       ' mm

A pose's rotation is R = Rz(rz)·Ry(ry)·Rx(rx) (fixed axes x, then y, then z); config is the
arm's configuration bits (SCONF), elbow the arm angle (deg).
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from strolic.codes import R8, Array, Num, TagHead, Vec
from strolic.functions.geometry import pose_of, vec_of
from strolic.values import data_of

from .source import Source, SourceError

LINE = re.compile(r"\s*(?P<kind>[A-Za-z]+)\s+(?P<name>[A-Za-z_]\w*)\s*=\s*(?P<values>.*?)\s*$")
NUMBER = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$")
COUNTS = {"POSE": (6, 8), "JOINT": (1, 16), "VECTOR": (3, 3)}
TYPES = {"POSE": "pose", "JOINT": "joint", "VECTOR": "vector"}


@dataclass(frozen=True)
class Point:
    name: str
    type: str           # pose, joint, vector
    value: object       # its STROLIC datum (Pm, Ar of R8, Vec)
    line: int


def rotation(rx: float, ry: float, rz: float) -> np.ndarray:
    """Rz·Ry·Rx of angles in degrees."""
    a, b, c = (math.radians(v) for v in (rx, ry, rz))
    Rx = np.array([[1, 0, 0], [0, math.cos(a), -math.sin(a)], [0, math.sin(a), math.cos(a)]])
    Ry = np.array([[math.cos(b), 0, math.sin(b)], [0, 1, 0], [-math.sin(b), 0, math.cos(b)]])
    Rz = np.array([[math.cos(c), -math.sin(c), 0], [math.sin(c), math.cos(c), 0], [0, 0, 1]])
    return Rz @ Ry @ Rx


def pose_value(values: list[float]):
    """x y z rx ry rz [config [elbow]] → a Pm of this VM's layout (positions in mm)."""
    matrix = np.eye(4)
    matrix[:3, :3] = rotation(*values[3:6])
    matrix[:3, 3] = values[:3]
    configuration = int(values[6]) if len(values) > 6 else 0
    elbow = values[7] if len(values) > 7 else 0.0
    return pose_of(matrix, configuration, elbow)


def joint_value(values: list[float]) -> Array:
    element = TagHead(R8)
    return Array(element, b"".join(data_of(Num(R8, float(v))) for v in values))


def vector_value(values: list[float]) -> Vec:
    return vec_of(values)


VALUES = {"POSE": pose_value, "JOINT": joint_value, "VECTOR": vector_value}


def parse_points(source: Source) -> dict[str, Point]:
    """The points of a taught-data file by upper-case name; SourceError for a bad line."""
    points: dict[str, Point] = {}
    for number, raw in enumerate(source.text.splitlines(), 1):
        text = raw.split("'", 1)[0]
        if not text.strip():
            continue
        match = LINE.match(text)
        if match is None or match["kind"].upper() not in COUNTS:
            column = len(text) - len(text.lstrip()) + 1
            raise SourceError(source, number, column, "expected POSE, JOINT or VECTOR, a name, "
                              "= and the values separated by commas")
        kind, name = match["kind"].upper(), match["name"]
        values = []
        column = match.start("values") + 1
        for item in match["values"].split(","):
            if not NUMBER.match(item.strip()):
                raise SourceError(source, number, column + len(item) - len(item.lstrip()),
                                  f"{item.strip()!r} is not a number")
            values.append(float(item))
            column += len(item) + 1
        low, high = COUNTS[kind]
        if not low <= len(values) <= high:
            count = str(low) if low == high else f"{low} to {high}"
            raise SourceError(source, number, match.start("values") + 1,
                              f"a {kind} takes {count} numbers, not {len(values)}")
        if name.upper() in points:
            raise SourceError(source, number, match.start("name") + 1,
                              f"{name} is taught twice (line {points[name.upper()].line})")
        points[name.upper()] = Point(name, TYPES[kind], VALUES[kind](values), number)
    return points
