"""The world in the live view: the world file's obstacles (once), the latest laser scan as
points, and the base's obstacle zones while it translates (caution yellow, stop red, on the
floor ahead of its footprint in the direction of travel). The base's state is in the panel."""
from __future__ import annotations

import math
from typing import Any, Callable

import numpy as np

from acti_sim.surroundings.scanner import LaserScanner, Scan
from acti_sim.surroundings.worldfile import WorldSpec

OBSTACLE = (158, 140, 115)
SCAN = (230, 30, 160)
CAUTION, STOP = (240, 190, 20), (220, 40, 40)
ZONE_Z = 0.004                # the zones' outlines just above the floor [m]


def add_obstacles(scene: Any, spec: WorldSpec) -> None:
    """Every obstacle of the world file as a solid, standing on the floor."""
    for i, b in enumerate(spec.boxes):
        x, y, yaw = b.pose
        scene.add_box(f"/world/box{i}", OBSTACLE, b.size, position=(x, y, b.size[2] / 2),
                      wxyz=(math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)))
    for i, c in enumerate(spec.cylinders):
        x, y, _ = c.pose
        scene.add_cylinder(f"/world/cylinder{i}", c.radius, c.height, OBSTACLE,
                           position=(x, y, c.height / 2))


def zone_outline(footprint: tuple[float, float, float, float], pose: tuple[float, float, float],
                 forward: bool, length: float) -> np.ndarray:
    """The zone's rectangle ahead of (or behind) the footprint as 4 line segments (4 × 2 × 3)."""
    x0, x1, y0, y1 = footprint
    near = x1 if forward else x0
    far = near + (length if forward else -length)
    corners = [(near, y0), (far, y0), (far, y1), (near, y1)]
    px, py, yaw = pose
    c, s = math.cos(yaw), math.sin(yaw)
    world = [(px + c * x - s * y, py + s * x + c * y, ZONE_Z) for x, y in corners]
    return np.array([[world[i], world[(i + 1) % 4]] for i in range(4)], np.float32)


class SurroundingsLayer:
    """Scene nodes of the world around the base, updated by the view's thread."""

    def __init__(self, spec: WorldSpec, scanner: LaserScanner | None,
                 latest_scan: Callable[[], Scan | None], base: Any,
                 footprint: tuple[float, float, float, float],
                 on_watch: Callable[[bool], None] = lambda watched: None) -> None:
        """`on_watch(watched)` is told whether a page is open (the scan is swept for it)."""
        self.spec, self.scanner, self.latest_scan = spec, scanner, latest_scan
        self.base, self.footprint, self.watched = base, footprint, on_watch
        self._angles = scanner.geometry.angles() if scanner is not None else None
        self._shown_scan: Scan | None = None
        self._zones: dict[str, Any] = {}

    def add(self, scene: Any) -> None:
        add_obstacles(scene, self.spec)

    def update(self, scene: Any, base_pose: tuple[float, float, float]) -> None:
        """The latest scan (when it changed) and the zones (while the base translates)."""
        scan = self.latest_scan()
        if scan is not None and scan is not self._shown_scan and self._angles is not None:
            self._shown_scan = scan
            points = scan.points(self._angles).astype(np.float32)
            if len(points):
                scene.add_point_cloud("/world/scan", points, SCAN, point_size=0.03,
                                      point_shape="circle")
        v = self.base.odometry.v
        if self.base.device.moving and abs(v) > 1e-3 and self.base.obstacle_watched:
            caution, stop = self.base.zones(abs(v))
            for name, length, color in (("caution", caution, CAUTION), ("stop", stop, STOP)):
                if length > 0:
                    self._zones[name] = scene.add_line_segments(
                        f"/world/zones/{name}",
                        zone_outline(self.footprint, base_pose, v > 0, length), color,
                        thickness=0.015)
        else:
            for handle in self._zones.values():
                handle.visible = False
            self._zones.clear()
