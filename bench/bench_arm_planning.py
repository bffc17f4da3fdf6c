"""Arm planning cost without ROS: time of one accept (checks + plan) per move kind and size,
from a fixed start (the queue is emptied between calls, so every plan starts there): wall time
and the thread's CPU time (steadier on a busy machine). Prints figures only (no timing asserts);
runs in a few seconds, and on older checkouts too (before/after comparisons). Arguments pick
the cases whose names contain them: `python bench/bench_arm_planning.py "20 mm" arc`."""
import math
import os
import sys
import time

import numpy as np
import pinocchio as pin
import toppra  # noqa: F401 - imported before timing, whichever way the code under test imports it

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from acti_motion.arm.core import ArmConfig, ArmCore, shared_kinematics  # noqa: E402
from acti_motion.arm.poses import pose_to_hg  # noqa: E402
from acti_motion.arm.trajectories import ArmSetpoint, ConstAccelTiming  # noqa: E402
from acti_motion.executor import MotionExecutor  # noqa: E402
from acti_sim.world import World  # noqa: E402

IDENTITY = np.eye(4)
REACHING = np.array([[1.0, 0.0, 0.0, 0.5], [0.0, -1.0, 0.0, -0.4], [0.0, 0.0, -1.0, 0.5],
                     [0.0, 0.0, 0.0, 1.0]])       # flange down, forward and to the right
RUNS = 15
SINGULAR_FROM = (20.0, 40.0, 10.0, -70.0, 30.0, 25.0, 0.0)
SINGULAR_TO = (-20.0, 40.0, -10.0, -70.0, -30.0, -25.0, 8.0)   # the wrist passes J6 = 0
# the costliest of 150 random CP lines between postures (accepted; refused: a joint would jump)
WORST_ACCEPTED = ((19.0, 69.0, 13.0, -51.0, -83.0, 1.0, 61.0),
                  (59.0, 83.0, -25.0, -102.0, -115.0, -27.0, 65.0))
WORST_REFUSED = ((-93.0, -1.0, 21.0, 7.0, 76.0, 36.0, 27.0),
                 (-81.0, 0.0, -30.0, -41.0, 93.0, 1.0, 17.0))


def rel(dx=0.0, dy=0.0, dz=0.0, rot=(0.0, 0.0, 0.0), elbow=0.0) -> tuple:
    m = np.eye(4)
    m[:3, :3] = pin.exp3(np.radians(rot))
    m[:3, 3] = np.array([dx, dy, dz]) / 1000.0
    return pose_to_hg(m), elbow, 0


def main() -> None:
    kin = shared_kinematics()
    reaching, steep = (np.degrees(kin.solve(REACHING, np.radians([0, 30, 0, -60, 0, 60, 0]),
                                            psi=math.radians(psi))) for psi in (-90.0, -120.0))
    world = World()
    ex = MotionExecutor(world, real_time_factor=0.0)
    arm = ArmCore(ex, ArmConfig(queue_size=4, initial_joints_deg=tuple(reaching)))
    arm.servo_on()
    arm.set_speed_joint(60)
    arm.set_speed_cartesian(100)

    def line_to(posture):
        q = np.radians(posture)
        target = (pose_to_hg(arm.tool_pose(q)), math.degrees(kin.arm_angle(q)), 0)
        return lambda: arm.move_linear_cartesian_abs(target)
    cases = [
        ("PTP joint 0.5° × 7", reaching, lambda: arm.move_ptp_joint_rel([0.5] * 7)),
        ("PTP joint 60° J1", reaching, lambda: arm.move_ptp_joint_rel([-60.0] + [0.0] * 6)),
        ("PTP Cartesian 200 mm", reaching, lambda: arm.move_ptp_cartesian_rel(rel(dy=200.0))),
        ("CP line 20 mm", reaching, lambda: arm.move_linear_cartesian_rel(rel(dx=20.0))),
        ("CP line 200 mm", reaching, lambda: arm.move_linear_cartesian_rel(rel(dy=200.0))),
        ("CP line 800 mm", reaching, lambda: arm.move_linear_cartesian_rel(rel(dy=800.0))),
        ("CP line 800 mm, J4 near 0", steep,
         lambda: arm.move_linear_cartesian_rel(rel(dy=800.0))),
        ("CP 300 mm + 30° turn", reaching,
         lambda: arm.move_linear_cartesian_rel(rel(dx=-100.0, dy=250.0, dz=150.0,
                                                   rot=(0.0, 0.0, 30.0)))),
        ("CP elbow 90°", reaching, lambda: arm.move_linear_cartesian_rel(rel(elbow=-90.0))),
        ("CP arc r 500 mm, 106°", reaching,
         lambda: arm.move_circular_cartesian_rel(rel(dx=200.0, dy=400.0), rel(dy=800.0))),
        ("CP near the wrist singularity", SINGULAR_FROM, line_to(SINGULAR_TO)),
        ("CP worst accepted of 150", WORST_ACCEPTED[0], line_to(WORST_ACCEPTED[1])),
        ("CP worst refused of 150", WORST_REFUSED[0], line_to(WORST_REFUSED[1])),
    ]
    print(f"one accept (checks + plan, no ROS) in ms, {RUNS} runs each: wall p50 and max, "
          "CPU p50")
    picked = sys.argv[1:]
    for name, start_deg, call in cases:
        if picked and not any(p in name for p in picked):
            continue
        start = ArmSetpoint(np.radians(start_deg), 0.0)
        walls, cpus, r = [], [], None
        for _ in range(RUNS + 1):                 # the first run warms up
            arm.device.halt(start, "the next run")
            t0, c0 = time.perf_counter(), time.thread_time()
            r = call()
            walls.append(time.perf_counter() - t0)
            cpus.append(time.thread_time() - c0)
        walls, cpus = 1e3 * np.array(walls[1:]), 1e3 * np.array(cpus[1:])
        if r.ok:
            motion = arm.device.queue[-1].motion
            samples = len(getattr(motion.path, "ss", ())) or "-"
            what = "TOPP-RA" if isinstance(motion.timing, ConstAccelTiming) else "trapezoid"
            what = f"{what:<9} samples {samples}"
        else:
            what = f"refused: {r.comment.split(': ', 1)[-1][:40]}"
        print(f"  {name:<30} wall {np.median(walls):7.2f} max {walls.max():7.2f}   "
              f"CPU {np.median(cpus):7.2f}   {what}")
    world.close()


if __name__ == "__main__":
    main()
