"""The laser scan's cost in the main job: a 10 Hz, 360-beam scan while both devices move in the
room (config/worlds/room.yaml), against the same job with the scanner off, measured in the same
run (runs alternate: off, on, off, on …).

Per run: the job (view off) at `real_time_factor` (default 1: what a user runs; 0: as fast as it
can, its capacity), the base cruising a square in the room's free middle, the arm cycling two
PTP moves, `scan` subscribed when on (the scanner casts only then). Measured over a window of
wall time: the real-time factor (simulated seconds per wall second, from `clock`), the job's CPU
per simulated second, and the control loop's falls behind (its log). The scan's CPU per simulated
second is the difference of the two; its ratio is on / off.

    python bench/bench_world.py [--rtf 1.0] [--seconds 20] [--rounds 2]
"""
from __future__ import annotations

import argparse
import re
import time

import numpy as np
from common import RosClient, cpu_seconds, ok, running

from acti_bringup.harness import FELL_BEHIND, wait_until
from acti_msgs import srv
from acti_msgs.msg import VehiclePoint, VehicleVelocity
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import LaserScan

ARM, BASE = "/acti_middle_node/", "/vehicle_node/"
SQUARE_MM = [(700.0, 700.0), (-700.0, 700.0), (-700.0, -700.0), (700.0, -700.0)]
POSES_DEG = ([30, 50, 0, -60, 0, 50, 0], [-30, 30, 20, -80, 0, 60, 0])


class Run:
    """One job: its simulated time from `clock` and its scans, while it moves."""

    def __init__(self, ros: RosClient, scan: bool) -> None:
        self.ros, self.scan = ros, scan
        self.clock = 0.0
        self.scans = 0
        self._subs = [ros.node.create_subscription(Clock, "/clock", self._on_clock, 10)]
        if scan:
            self._subs.append(ros.node.create_subscription(LaserScan, "/scan", self._on_scan, 10))

    def _on_clock(self, msg: Clock) -> None:
        self.clock = msg.clock.sec + msg.clock.nanosec * 1e-9

    def _on_scan(self, msg: LaserScan) -> None:
        self.scans += 1

    def close(self) -> None:
        for s in self._subs:
            self.ros.node.destroy_subscription(s)

    def keep_moving(self) -> None:
        """Queue another lap of the square and two arm moves when the queues run low."""
        ros = self.ros
        base = ros.call(srv.VehicleGetState, BASE + "get_state")
        if base.state == 0x010:
            for x, y in SQUARE_MM:
                ok(ros.call(srv.VehicleMoveCruiseAbs, BASE + "move_cruise_abs",
                            cruise_point=VehiclePoint(x=x, y=y)))
        arm = ros.call(srv.GetState, ARM + "get_state")
        if not arm.state & 0x2:        # not moving: queue the two poses again
            for q in POSES_DEG:
                ok(ros.call(srv.MovePTPJointAbs, ARM + "move_ptp_joint_abs",
                            joint_points=[float(v) for v in q]))


def measure(ros: RosClient, scan: bool, rtf: float, seconds: float) -> dict[str, float]:
    params = ("world:=config/worlds/room.yaml", "view_enabled:=false", f"real_time_factor:={rtf}",
              f"scan_rate_hz:={10.0 if scan else 0.0}", "scan_beams:=360")
    with running("acti_bringup", *params) as job:
        run = Run(ros, scan)
        try:
            ok(ros.call(srv.VehicleSetPower, BASE + "set_power", on_off=True))
            ok(ros.call(srv.VehicleSetServo, BASE + "set_servo", on_off=True))
            ok(ros.call(srv.VehicleSetVelocity, BASE + "set_velocity",
                        vel=VehicleVelocity(translation=500.0, rotation=60.0)))
            ok(ros.call(srv.ServoON, ARM + "servo_on"))
            ok(ros.call(srv.SetSpeedJoint, ARM + "set_speed_joint", spd_ratio=30))
            run.keep_moving()
            assert ros.spin_until(lambda: run.clock > 0 and (run.scans or not scan), 60.0)
            ros.spin_until(lambda: False, 2.0)                  # under way
            falls0 = len(re.findall(FELL_BEHIND, job.log()))
            sim0, cpu0, wall0, scans0 = run.clock, cpu_seconds(job.proc.pid), time.monotonic(), run.scans
            while time.monotonic() - wall0 < seconds:
                run.keep_moving()
                ros.spin_until(lambda: False, 0.5)
            sim1, cpu1, wall1 = run.clock, cpu_seconds(job.proc.pid), time.monotonic()
            falls = len(re.findall(FELL_BEHIND, job.log())) - falls0
            assert wait_until(job.alive, 1.0), job.log()
        finally:
            run.close()
    simulated = sim1 - sim0
    return {"rtf": simulated / (wall1 - wall0), "cpu_per_sim_s": (cpu1 - cpu0) / simulated,
            "falls": falls, "scan_hz": (run.scans - scans0) / simulated}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rtf", type=float, default=1.0, help="the job's real_time_factor")
    parser.add_argument("--seconds", type=float, default=20.0, help="wall seconds per run")
    parser.add_argument("--rounds", type=int, default=2, help="off/on pairs")
    a = parser.parse_args()
    ros = RosClient()
    results: dict[bool, list[dict[str, float]]] = {False: [], True: []}
    for _ in range(a.rounds):
        for scan in (False, True):
            r = measure(ros, scan, a.rtf, a.seconds)
            results[scan].append(r)
            print(f"  scan {'on ' if scan else 'off'}: real-time factor {r['rtf']:.3f}, "
                  f"CPU {1000 * r['cpu_per_sim_s']:.0f} ms per simulated s, "
                  f"{r['scan_hz']:.1f} scans per simulated s, {r['falls']} falls behind", flush=True)
    ros.close()

    def mean(scan: bool, key: str) -> float:
        return float(np.mean([r[key] for r in results[scan]]))
    off, on = mean(False, "cpu_per_sim_s"), mean(True, "cpu_per_sim_s")
    print(f"\nroom, both devices moving, real_time_factor {a.rtf:g}, {a.rounds} × {a.seconds:g} s "
          "per configuration, alternating")
    print(f"{'':24}{'scan off':>12}{'scan on':>12}{'on / off':>10}")
    print(f"{'real-time factor':24}{mean(False, 'rtf'):12.3f}{mean(True, 'rtf'):12.3f}"
          f"{mean(True, 'rtf') / mean(False, 'rtf'):10.3f}")
    print(f"{'CPU ms / simulated s':24}{1000 * off:12.0f}{1000 * on:12.0f}{on / off:10.3f}")
    print(f"the scan (10 Hz, 360 beams): {1000 * (on - off):.0f} ms of CPU per simulated second "
          f"({100 * (on - off):.1f} % of a core at real time); goal: real-time factor >= 1.0 "
          f"with it: {mean(True, 'rtf'):.3f}")


if __name__ == "__main__":
    main()
