"""A detour around an obstacle on the known map (the world file's occupancy grid), for Avoid.

The base first backs straight up until it may turn in place (its circumscribed circle clear of
every occupied cell), then follows the shortest 8-connected grid path (A*) through cells where
that circle stays clear, cut to the few straight legs that keep it clear (line of sight). The
result is the base's waypoints in the map's frame; None when no such path exists.
"""
from __future__ import annotations

import heapq
import math

import numpy as np
from scipy.ndimage import distance_transform_edt

from acti_motion.vehicle.paths import Pose2D
from acti_sim.surroundings.occupancy import OCCUPIED, Grid

MAX_BACKUP_M = 1.0        # the farthest the base backs up before turning
SQRT2 = math.sqrt(2.0)


def clearance(grid: Grid) -> np.ndarray:
    """Each cell's distance to the nearest occupied cell [m] (off the map is free floor)."""
    free = grid.cells != OCCUPIED
    if free.all():
        return np.full(free.shape, np.inf)
    return distance_transform_edt(free) * grid.resolution - grid.resolution / 2


def plan_detour(grid: Grid, start: Pose2D, goal: Pose2D, radius: float,
                reversing: bool = False) -> list[tuple[float, float]] | None:
    """Waypoints (m, map frame) from `start` to `goal` for a base of circumscribed `radius`;
    the first is where the backing up (away from the obstacle: forwards when the base was
    `reversing` into it) ends."""
    grid = grid.covering([(start.x, start.y), (goal.x, goal.y)], MAX_BACKUP_M + 2 * radius)
    room = clearance(grid)

    def clear(x: float, y: float) -> bool:
        r, c = grid.cell_of(x, y)
        return 0 <= r < room.shape[0] and 0 <= c < room.shape[1] and room[r, c] >= radius

    back = _backed_up(start, clear, grid.resolution * (1.0 if reversing else -1.0))
    if back is None or not clear(goal.x, goal.y):
        return None
    cells = _a_star(room >= radius, grid.cell_of(back.x, back.y), grid.cell_of(goal.x, goal.y))
    if cells is None:
        return None
    points = [(grid.origin[0] + (c + 0.5) * grid.resolution,
               grid.origin[1] + (r + 0.5) * grid.resolution) for r, c in cells]
    points = [(back.x, back.y), *points[1:-1], (goal.x, goal.y)]
    return _in_sight(points, clear, grid.resolution)


def _backed_up(start: Pose2D, clear, step: float) -> Pose2D | None:
    """The nearest pose straight along `start`'s heading by steps of `step` (negative: behind
    it) where the base may turn."""
    for k in range(int(MAX_BACKUP_M / abs(step)) + 1):
        here = start.forward(k * step)
        if clear(here.x, here.y):
            return here
    return None


def _a_star(passable: np.ndarray, start: tuple[int, int], goal: tuple[int, int]):
    """The cells of a shortest 8-connected path (inclusive), or None."""
    rows, cols = passable.shape
    if not (0 <= goal[0] < rows and 0 <= goal[1] < cols):
        return None
    cost = {start: 0.0}
    came: dict[tuple[int, int], tuple[int, int]] = {}
    frontier = [(0.0, start)]
    steps = [(dr, dc, SQRT2 if dr and dc else 1.0)
             for dr in (-1, 0, 1) for dc in (-1, 0, 1) if dr or dc]
    while frontier:
        _, cell = heapq.heappop(frontier)
        if cell == goal:
            path = [cell]
            while cell in came:
                cell = came[cell]
                path.append(cell)
            return path[::-1]
        r, c = cell
        for dr, dc, d in steps:
            n = (r + dr, c + dc)
            if not (0 <= n[0] < rows and 0 <= n[1] < cols) or not passable[n]:
                continue
            new = cost[cell] + d
            if new < cost.get(n, math.inf):
                cost[n], came[n] = new, cell
                heapq.heappush(frontier, (new + math.hypot(goal[0] - n[0], goal[1] - n[1]), n))
    return None


def _in_sight(points: list[tuple[float, float]], clear, step: float) -> list[tuple[float, float]]:
    """The fewest of `points` (first and last kept) whose straight legs stay clear."""
    def visible(a, b) -> bool:
        n = max(1, int(math.hypot(b[0] - a[0], b[1] - a[1]) / (step / 2)))
        return all(clear(a[0] + (b[0] - a[0]) * k / n, a[1] + (b[1] - a[1]) * k / n)
                   for k in range(n + 1))
    out, i = [points[0]], 0
    while i < len(points) - 1:
        j = len(points) - 1
        while j > i + 1 and not visible(points[i], points[j]):
            j -= 1
        out.append(points[j])
        i = j
    return out
