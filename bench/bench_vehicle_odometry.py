"""Wheel odometry against the simulator's ground truth: a 500 mm move, turns in place, and a 5 m
square driven with moveLinearAbs (turn, straight, turn at each corner) and with moveCruiseAbs.
As in the main job: 250 Hz, the arm held in its start posture (its weight ahead of the wheel
axle is what the wheels must carry round in a turn). No ROS."""
from __future__ import annotations

import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from acti_motion.arm.core import ArmConfig, ArmCore  # noqa: E402
from acti_motion.executor import MotionExecutor  # noqa: E402
from acti_motion.vehicle.core import VehicleCore  # noqa: E402
from acti_sim.world import World  # noqa: E402

TURNS = [90.0, 90.0, -180.0, 360.0] * 2
SQUARE = [(5000.0, 0.0, 90.0), (5000.0, 5000.0, 180.0), (0.0, 5000.0, -90.0), (0.0, 0.0, 0.0)]


class Run:
    def __init__(self) -> None:
        self.world = World(time_step=0.004)
        self.executor = MotionExecutor(self.world, real_time_factor=0.0)
        self.arm = ArmCore(self.executor, ArmConfig())
        self.base = VehicleCore(self.executor)
        self.base.set_power(True)
        self.base.set_servo(True)
        self.base.set_velocity((500.0, 45.0))
        for _ in range(120):
            self.executor.step()
        self.base.set_position((0.0, 0.0, 0.0))
        self.truth0 = self.world.base_pose()

    def settle(self) -> None:
        while self.base.device.busy:
            self.executor.step()

    def error(self) -> tuple[float, float, float]:
        """(odometry - truth) in the start frame: position mm, heading degree, and truth (mm)."""
        x0, y0, th0 = self.truth0
        x, y, th = self.world.base_pose()
        c, s = math.cos(th0), math.sin(th0)
        tx, ty = c * (x - x0) + s * (y - y0), -s * (x - x0) + c * (y - y0)
        p = self.base.odometry.pose
        dpos = 1000.0 * math.hypot(p.x - tx, p.y - ty)
        dth = math.degrees(math.remainder(p.theta - (th - th0), 2 * math.pi))
        return dpos, dth, 1000.0 * math.hypot(tx, ty)


def main() -> None:
    run = Run()
    run.base.move_forward(500.0)
    run.settle()
    dpos, dth, truth = run.error()
    print(f"500 mm forward: odometry {1000.0 * run.base.odometry.pose.x:.2f} mm, ground truth "
          f"{truth:.2f} mm: {dpos:.2f} mm apart ({100.0 * dpos / 500.0:.2f} %), heading {dth:+.3f} deg")
    run.world.close()

    run = Run()
    moved = []
    for angle in TURNS:
        before = run.world.base_link_pose()[0]
        run.base.move_turn(angle)
        run.settle()
        after = run.world.base_link_pose()[0]
        moved.append(1000.0 * math.hypot(after[0] - before[0], after[1] - before[1]))
    dpos, dth, _ = run.error()
    print(f"{len(TURNS)} turns in place ({', '.join(f'{a:+.0f}' for a in TURNS)} deg): the axle "
          f"centre moved {min(moved):.1f} … {max(moved):.1f} mm per turn; odometry - truth "
          f"{dpos:.1f} mm, heading {dth:+.3f} deg")
    run.world.close()

    run = Run()
    print("5 m square, move_linear_abs to each corner (500 mm/s, 45 deg/s):")
    travelled = 0.0
    for corner in SQUARE:
        run.base.move_linear_abs(corner)
        run.settle()
        travelled += 5.0
        dpos, dth, _ = run.error()
        print(f"  corner {corner[0]:6.0f} {corner[1]:6.0f}: odometry - truth {dpos:6.1f} mm "
              f"({dpos / travelled / 10.0:.3f} % of {travelled:.0f} m), heading {dth:+.3f} deg")
    run.world.close()

    run = Run()
    for x, y, _ in SQUARE:
        run.base.move_cruise_abs((x, y))
    run.settle()
    dpos, dth, _ = run.error()
    print(f"5 m square as one cruise (rounded corners): odometry - truth {dpos:.1f} mm, heading {dth:+.3f} deg")
    run.world.close()


if __name__ == "__main__":
    main()
