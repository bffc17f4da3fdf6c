"""Figures for docs/performance.md from real runs on the simulation (the cores on their own world, no ROS):

  docs/cp_move.png  a CP move through the wrist singularity: the control point's measured speed
                    along the path, the planned speed and the TOPP-RA time-optimal bound
  docs/cruise.png   a moveCruiseAbs through five points: planned path, odometry and ground truth;
                    speed against time, planned and executed, with the TOPP-RA bound

    python bench/plot_runs.py [OUT_DIR]
"""
from __future__ import annotations

import math
import os
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from bench_arm import ARM_START  # noqa: E402
from bench_vehicle_cruise import POINTS_MM, SETTINGS  # noqa: E402
from common import simulated_arm, simulated_base  # noqa: E402

from acti_motion.arm.poses import pose_to_hg  # noqa: E402
from acti_motion.arm.trajectories import CartesianLimits, LinePath, time_optimal  # noqa: E402
from acti_motion.vehicle.cruise import spline_through  # noqa: E402
from acti_motion.vehicle.cruise import time_optimal as cruise_bound  # noqa: E402
from acti_motion.vehicle.paths import Pose2D  # noqa: E402


def cp_move(out: str) -> None:
    world, ex, arm = simulated_arm(ARM_START, 60)
    arm.set_speed_cartesian(100)
    arm.move_ptp_joint_abs([20, 40, 10, -70, 30, 25, 0])
    while arm.device.busy:
        ex.step()
    P0 = arm.tool_pose(arm.device.hold.joints)
    target = arm.tool_pose(np.radians([-20, 40, -10, -70, -30, -25, 8]))
    elbow = math.degrees(arm.kin.arm_angle(arm.device.hold.joints))
    assert arm.move_linear_cartesian_abs((pose_to_hg(target), elbow, 0)).ok
    motion = arm.device.queue[0].motion
    line = LinePath(P0, target)
    v, w = arm.max_speed_cartesian
    limits = CartesianLimits(v / 1000, math.radians(w), arm.accel_time_cartesian,
                             np.radians(arm.max_speed_joint),
                             np.radians(arm.max_speed_joint) / arm.min_accel_time_joint)
    bound = time_optimal(motion.path.ss, motion.path.qs, np.array([line.length, line.angle, 0.0]),
                         limits)
    direction = (target[:3, 3] - P0[:3, 3]) / line.length
    times, along = [], []
    t0 = world.time
    while arm.device.busy:
        ex.step()
        times.append(world.time - t0)
        along.append(np.dot(arm.tool_pose(world.arm_positions())[:3, 3] - P0[:3, 3], direction))
    world.close()
    times, along = np.array(times), 1000.0 * np.array(along)
    speed = np.gradient(along, times)

    def profile(timing):
        ts = np.linspace(0.0, timing.duration, 400)
        s, sd = np.array([timing.sample(t) for t in ts]).T
        return 1000.0 * line.length * s, 1000.0 * line.length * sd
    fig, ax = plt.subplots(figsize=(7.5, 3.6))
    ax.plot(*profile(bound), "k--", lw=2.2, label=f"TOPP-RA bound ({bound.duration:.2f} s)")
    ax.plot(*profile(motion.timing), color="tab:blue", lw=1.5,
            label=f"planned ({motion.duration:.2f} s)")
    ax.plot(along, speed, color="tab:orange", lw=1.0, label="measured in the simulation")
    ax.axhline(v, color="grey", lw=0.8, ls=":", label=f"Cartesian speed limit {v:g} mm/s")
    ax.set(xlabel="distance along the line [mm]", ylabel="control point speed [mm/s]",
           title=f"CP move near the wrist singularity, {1000 * line.length:.0f} mm at 100 %")
    ax.legend(fontsize=8, loc="center")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(out, dpi=90)


def cruise(out: str) -> None:
    world, ex, base = simulated_base(*SETTINGS)
    for p in POINTS_MM:
        assert base.move_cruise_abs(p).ok
    planned = base.device.queue[0].motion.path
    t0, rows = world.time, []
    while base.device.busy:
        ex.step()
        o = base.odometry
        rows.append((world.time - t0, 1000 * o.pose.x, 1000 * o.pose.y, 1000 * o.v,
                     *(1000 * np.array(world.base_pose()[:2]))))
    world.close()
    t, x, y, v, gx, gy = np.array(rows).T
    limits = (SETTINGS[0][0] / 1000.0, math.radians(SETTINGS[0][1]),
              SETTINGS[1][0] / 1000.0, math.radians(SETTINGS[1][1]))
    s, _, _, heading, _ = spline_through(Pose2D(0.0, 0.0, 0.0),
                                         [(a / 1000.0, b / 1000.0) for a, b in POINTS_MM])
    bound = cruise_bound(s, heading, limits, grid_step=0.001, grid_max=20000)
    tb = np.linspace(0.0, bound.duration, 600)

    fig, (top, bottom) = plt.subplots(2, 1, figsize=(7.5, 6.0))
    tp = np.linspace(0.0, planned.duration, 800)
    plan_xy = 1000 * np.array([(q.x, q.y) for q in map(planned.pose, tp)])
    plan_v = 1000 * np.array([planned.twist(ti)[0] for ti in tp])
    top.plot(*plan_xy.T, "k--", lw=2, label="planned spline")
    top.plot(x, y, color="tab:blue", lw=1.2, label="odometry")
    top.plot(gx, gy, color="tab:orange", lw=1.0, label="ground truth")
    top.plot(*zip(*POINTS_MM), "ro", ms=5, label="cruise points")
    top.set(xlabel="x [mm]", ylabel="y [mm]", aspect="equal",
            title=f"moveCruiseAbs through {len(POINTS_MM)} points "
                  f"(v {SETTINGS[0][0]:g} mm/s, a {SETTINGS[1][0]:g} mm/s²)")
    top.set_ylim(-300, 1300)
    top.legend(fontsize=8, ncol=4, loc="upper center")
    bottom.plot(tb, 1000 * bound(tb, 1)[:, 0], "k--", lw=2,
                label=f"TOPP-RA bound, 1 mm grid ({bound.duration:.2f} s)")
    bottom.plot(tp, plan_v, color="tab:blue", lw=1.5,
                label=f"planned ({planned.duration:.2f} s)")
    bottom.plot(t, v, color="tab:orange", lw=1.0, label="executed (odometry)")
    bottom.set(xlabel="time [s]", ylabel="speed [mm/s]")
    bottom.legend(fontsize=8, loc="lower center")
    for a in (top, bottom):
        a.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(out, dpi=90)


def main() -> None:
    out_dir = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "docs")
    os.makedirs(out_dir, exist_ok=True)
    for name, make in (("cp_move.png", cp_move), ("cruise.png", cruise)):
        make(os.path.join(out_dir, name))
        print(f"wrote {os.path.join(out_dir, name)}")


if __name__ == "__main__":
    main()
