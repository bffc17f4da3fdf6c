"""The world file's obstacles as an occupancy grid, and Nav2's map-server pair (.yaml + .pgm).

A cell is occupied when an obstacle's footprint overlaps its square at all (not only its centre):
a wall thinner than a cell still closes the map. The grid covers the obstacles and the robot's
start (the origin) with a margin around them.
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass

import numpy as np

from acti_sim.surroundings.worldfile import WorldSpec

OCCUPIED = 100
FREE = 0
MARGIN_M = 1.0            # free floor kept around the obstacles and the start [m]
# map-server's thresholds for the .pgm (its defaults): darker than occupied_thresh is occupied
OCCUPIED_THRESH = 0.65
FREE_THRESH = 0.25


@dataclass(frozen=True)
class Grid:
    """Row-major cells, row 0 at `origin`'s y (the bottom, as nav_msgs/OccupancyGrid has it)."""
    resolution: float                 # [m/cell]
    origin: tuple[float, float]       # the lower-left corner of cell (0, 0), world frame [m]
    cells: np.ndarray                 # int8, (height, width): 0 free, 100 occupied

    @property
    def width(self) -> int:
        return int(self.cells.shape[1])

    @property
    def height(self) -> int:
        return int(self.cells.shape[0])

    def covering(self, points: list[tuple[float, float]], margin: float = MARGIN_M) -> "Grid":
        """This grid grown with free cells until it holds every point with `margin` around it
        (the world file lists every obstacle: off the map is free floor)."""
        res, (x0, y0) = self.resolution, self.origin
        xs, ys = [p[0] for p in points], [p[1] for p in points]
        left = max(0, math.ceil((x0 - (min(xs) - margin)) / res))
        below = max(0, math.ceil((y0 - (min(ys) - margin)) / res))
        right = max(0, math.ceil((max(xs) + margin - (x0 + self.width * res)) / res))
        above = max(0, math.ceil((max(ys) + margin - (y0 + self.height * res)) / res))
        if not (left or below or right or above):
            return self
        cells = np.pad(self.cells, ((below, above), (left, right)), constant_values=FREE)
        return Grid(res, (x0 - left * res, y0 - below * res), cells)

    def cell_of(self, x: float, y: float) -> tuple[int, int]:
        """(row, column) of the cell that holds the point (x, y)."""
        return (int(math.floor((y - self.origin[1]) / self.resolution)),
                int(math.floor((x - self.origin[0]) / self.resolution)))


def rasterise(world: WorldSpec, resolution: float) -> Grid:
    """The world's obstacles on a grid of `resolution` metres per cell."""
    x0, y0, x1, y1 = world.bounds() or (0.0, 0.0, 0.0, 0.0)
    x0, y0 = min(x0, 0.0) - MARGIN_M, min(y0, 0.0) - MARGIN_M
    x1, y1 = max(x1, 0.0) + MARGIN_M, max(y1, 0.0) + MARGIN_M
    width, height = math.ceil((x1 - x0) / resolution), math.ceil((y1 - y0) / resolution)
    half = resolution / 2
    cx = x0 + half + resolution * np.arange(width)
    cy = y0 + half + resolution * np.arange(height)
    gx, gy = np.meshgrid(cx, cy)
    occupied = np.zeros((height, width), bool)
    for b in world.boxes:
        x, y, yaw = b.pose
        c, s = math.cos(yaw), math.sin(yaw)
        dx, dy = gx - x, gy - y
        # separating axes of two rectangles: the grid's (the box's bounding box) and the box's
        ex = abs(c) * b.size[0] / 2 + abs(s) * b.size[1] / 2
        ey = abs(s) * b.size[0] / 2 + abs(c) * b.size[1] / 2
        reach = half * (abs(c) + abs(s))
        occupied |= ((np.abs(dx) <= ex + half) & (np.abs(dy) <= ey + half)
                     & (np.abs(dx * c + dy * s) <= b.size[0] / 2 + reach)
                     & (np.abs(-dx * s + dy * c) <= b.size[1] / 2 + reach))
    for cyl in world.cylinders:
        x, y, _ = cyl.pose
        nearest_x = np.clip(x, gx - half, gx + half)
        nearest_y = np.clip(y, gy - half, gy + half)
        occupied |= (nearest_x - x) ** 2 + (nearest_y - y) ** 2 <= cyl.radius ** 2
    cells = np.where(occupied, OCCUPIED, FREE).astype(np.int8)
    return Grid(resolution, (x0, y0), cells)


def write_map_server_pair(grid: Grid, yaml_path: str) -> str:
    """Write `yaml_path` and the .pgm beside it, as Nav2's map_saver does (trinary: occupied
    black, free white); returns the .pgm's path."""
    pgm_path = os.path.splitext(yaml_path)[0] + ".pgm"
    image = np.where(grid.cells[::-1] == OCCUPIED, 0, 254).astype(np.uint8)   # top row first
    with open(pgm_path, "wb") as f:
        f.write(f"P5\n# acti_ros2 world map\n{grid.width} {grid.height}\n255\n".encode())
        f.write(image.tobytes())
    with open(yaml_path, "w") as f:
        f.write(f"image: {os.path.basename(pgm_path)}\n"
                f"mode: trinary\n"
                f"resolution: {grid.resolution:g}\n"
                f"origin: [{grid.origin[0]:g}, {grid.origin[1]:g}, 0.0]\n"
                f"negate: 0\n"
                f"occupied_thresh: {OCCUPIED_THRESH}\n"
                f"free_thresh: {FREE_THRESH}\n")
    return pgm_path
