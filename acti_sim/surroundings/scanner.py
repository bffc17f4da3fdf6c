"""A planar laser scanner on a link of the robot, by batched PyBullet ray casts.

It sweeps as a rotating scanner does: each call of `advance` casts the beams that fall due since
the last one (a slice of the sweep), so a scan's ray casting is spread over the simulation steps
of its period instead of landing on one of them, and the beams of one scan are taken at the
times `time_increment` says. The robot's own links are not seen (`World.cast_rays`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from acti_sim.world import World


@dataclass(frozen=True)
class ScanGeometry:
    fov: float               # field of view [rad], centred on the link's +x
    beams: int               # beams per scan, evenly spaced from -fov/2 to +fov/2
    range_min: float         # [m]
    range_max: float         # [m]
    noise: float             # standard deviation of the Gaussian range noise [m]; 0: exact

    @property
    def angle_min(self) -> float:
        return -self.fov / 2

    @property
    def angle_increment(self) -> float:
        """A full circle does not repeat its first beam at its end."""
        full = self.fov >= 2 * math.pi - 1e-9
        return self.fov / (self.beams if full else max(self.beams - 1, 1))

    def angles(self) -> np.ndarray:
        return self.angle_min + self.angle_increment * np.arange(self.beams)


@dataclass
class Scan:
    """One finished sweep: ranges [m] (inf: no return within range_max), when it began, and
    where the scanner was when it ended (x, y, z [m], yaw [rad] in the world: for a view)."""
    start_time: float
    ranges: np.ndarray
    pose: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)

    def points(self, angles: np.ndarray) -> np.ndarray:
        """The returns as points in the world (n × 3), from `pose` (the robot's motion during the
        sweep is not undone)."""
        x, y, z, yaw = self.pose
        hit = np.isfinite(self.ranges)
        r, a = self.ranges[hit], angles[hit] + yaw
        return np.stack([x + r * np.cos(a), y + r * np.sin(a), np.full_like(r, z)], 1)


def rotation_matrix(q: tuple[float, float, float, float]) -> np.ndarray:
    """The 3×3 rotation of a unit quaternion (x, y, z, w)."""
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


class LaserScanner:
    """Sweeps `geometry` from `link` once per `period` seconds of simulated time."""

    def __init__(self, link: str, geometry: ScanGeometry, period: float, seed: int = 0) -> None:
        self.link, self.geometry, self.period = link, geometry, period
        angles = geometry.angles()
        self._directions = np.stack([np.cos(angles), np.sin(angles), np.zeros_like(angles)], 1)
        self._ranges = np.full(geometry.beams, math.inf)
        self._next = 0                 # the next beam to cast
        self._start: float | None = None   # the sweep's start time (the next one's, between)
        self._rng = np.random.default_rng(seed)

    @property
    def time_increment(self) -> float:
        return self.period / self.geometry.beams

    def advance(self, world: World) -> Scan | None:
        """Cast the beams due by `world.time`; the finished scan when the sweep ends. Sweeps
        start a period apart (or now, after a pause of more than a period)."""
        if self._start is None or world.time - self._start > 2 * self.period:
            self._start, self._next = world.time, 0
        if world.time < self._start - 1e-9:
            return None                                 # the next sweep is not due yet
        due = math.floor((world.time - self._start) / self.time_increment + 1e-9) + 1
        end = min(self.geometry.beams, max(due, self._next + 1))
        self._cast(world, self._next, end)
        self._next = end
        if end < self.geometry.beams:
            return None
        scan = Scan(self._start, self._ranges.copy(), self._pose(world))
        self._next, self._start = 0, self._start + self.period
        return scan

    def scan_now(self, world: World) -> Scan:
        """A whole sweep at once (tests, one-off views)."""
        self._cast(world, 0, self.geometry.beams)
        return Scan(world.time, self._ranges.copy(), self._pose(world))

    def _pose(self, world: World) -> tuple[float, float, float, float]:
        (x, y, z), q = world.link_pose(self.link)
        r = rotation_matrix(q)
        return x, y, z, math.atan2(r[1, 0], r[0, 0])

    def _cast(self, world: World, first: int, end: int) -> None:
        g = self.geometry
        position, orientation = world.link_pose(self.link)
        origin = np.asarray(position)
        rotation = rotation_matrix(orientation)
        directions = self._directions[first:end] @ rotation.T
        starts = origin + g.range_min * directions
        ends = origin + g.range_max * directions
        fractions = world.cast_rays(starts.tolist(), ends.tolist())
        ranges = g.range_min + fractions * (g.range_max - g.range_min)
        if g.noise > 0:
            ranges = ranges + self._rng.normal(0.0, g.noise, len(ranges))
        self._ranges[first:end] = np.where(fractions >= 1.0, math.inf,
                                           np.clip(ranges, g.range_min, g.range_max))
