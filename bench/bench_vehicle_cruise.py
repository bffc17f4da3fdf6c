"""moveCruiseAbs against the time-optimal bound: the same path (spline through the points) and
limits, timed by TOPP-RA on a fine grid. Simulated seconds; no ROS (the core on its own world)."""
from __future__ import annotations

import math
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from common import simulated_base  # noqa: E402

from acti_motion.vehicle.paths import Pose2D  # noqa: E402
from acti_motion.vehicle.cruise import plan_curve, spline_through, time_optimal  # noqa: E402

POINTS_MM = [(1000.0, 0.0), (2000.0, 600.0), (3000.0, 0.0), (4000.0, 600.0), (5000.0, 0.0)]
SETTINGS = ((800.0, 90.0), (500.0, 180.0))          # velocity, acceleration (mm, degree)


def main() -> None:
    world, executor, base = simulated_base(*SETTINGS)
    wall = []
    for p in POINTS_MM:
        t0 = time.perf_counter()
        base.move_cruise_abs(p)
        wall.append(time.perf_counter() - t0)
    motion = base.device.queue[0].motion
    planned = motion.path.duration
    t0, within, closest, slowest = world.time, None, {p: math.inf for p in POINTS_MM}, math.inf
    last = POINTS_MM[-1]
    while base.device.busy:
        executor.step()
        pose = base.odometry.pose
        here = (1000.0 * pose.x, 1000.0 * pose.y)
        for p in POINTS_MM:
            closest[p] = min(closest[p], math.dist(here, p))
        if within is None and math.dist(here, last) < 5.0 and abs(base.odometry.v) < 0.01:
            within = world.time - t0
        if closest[POINTS_MM[0]] < 10.0 and math.dist(here, last) > 100.0:
            slowest = min(slowest, base.odometry.v)
    done = world.time - t0

    limits = (SETTINGS[0][0] / 1000.0, math.radians(SETTINGS[0][1]),
              SETTINGS[1][0] / 1000.0, math.radians(SETTINGS[1][1]))
    points = [(x / 1000.0, y / 1000.0) for x, y in POINTS_MM]
    s, _, _, heading, _ = spline_through(Pose2D(0.0, 0.0, 0.0), points)
    bound = time_optimal(s, heading, limits, grid_step=0.001, grid_max=20000).duration
    check = plan_curve(Pose2D(0.0, 0.0, 0.0), points, limits).path.duration
    world.close()

    print(f"cruise through {len(POINTS_MM)} points, {s[-1]:.2f} m of path; limits v {SETTINGS[0][0]:g} mm/s, "
          f"w {SETTINGS[0][1]:g} deg/s, a {SETTINGS[1][0]:g} mm/s2, alpha {SETTINGS[1][1]:g} deg/s2")
    print(f"  time-optimal bound (TOPP-RA, 1 mm grid)   {bound:7.3f} s")
    print(f"  planned (TOPP-RA ConstAccel, 1 cm grid)   {planned:7.3f} s   ratio {planned / bound:6.4f}"
          f"   (same plan again: {check:.3f} s)")
    print(f"  executed, at rest within 5 mm of the end  {within:7.3f} s   ratio {within / bound:6.4f}")
    print(f"  executed, motion done (incl. 0.4 s settle) {done:6.3f} s")
    print(f"  slowest between the first point and 100 mm before the last: {1000.0 * slowest:.0f} mm/s")
    print("  closest approach to each point (mm): " + ", ".join(f"{closest[p]:.2f}" for p in POINTS_MM))
    print(f"  planning per move_cruise_abs call (wall): mean {1000 * sum(wall) / len(wall):.1f} ms, "
          f"max {1000 * max(wall):.1f} ms (first includes the toppra import)")


if __name__ == "__main__":
    main()
