"""How many robots one machine runs in real time.

Starts robots one at a time, each a main job in its own namespace (`python -m acti_bringup
--ros-args -r __ns:=/robotK`), all in one ROS domain. After each start it measures every robot
over a window idle, then over a window moving (every arm swings between two poses, every base turns
on the spot): its CPU (% of one core, from /proc) and its real-time factor (simulated seconds of
its /robotK/clock per wall second). It stops at the first count with a robot out of
real time (its RTF off 1 by more than 1 %: below, it falls behind; above, it catches up after
falling behind) and prints the largest count that kept real time.

    python bench/bench_scale.py [--max 10] [--window 10] [--rate 250]
"""
from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from dataclasses import dataclass, field

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import RosClient  # noqa: E402  (sets up DDS before rclpy loads)

from acti_bringup.harness import NodeProcess, wait_until  # noqa: E402

from acti_msgs import srv  # noqa: E402
from rosgraph_msgs.msg import Clock  # noqa: E402

REAL_TIME_TOLERANCE = 0.01        # a robot keeps real time when its RTF over the window is 1 within this:
                        # above 1 it is catching up after falling behind
SETTLE_S = 3.0          # after a start or a burst of commands, before a window
CLOCK_RATE_HZ = 10.0    # the clock the bench reads (each robot publishes it only while read)
TICKS = os.sysconf("SC_CLK_TCK")
POSES = ([0.0, 30.0, 0.0, -60.0, 0.0, 60.0, 0.0], [40.0, 50.0, 20.0, -90.0, 30.0, 30.0, 40.0])
MOVES = 24              # arm moves queued: longer than a window at the bench's speed
TURNS = 10              # base turns (one motion: the base takes no new move while busy)


@dataclass
class Robot:
    namespace: str
    process: NodeProcess
    clock: list[tuple[float, float]] = field(default_factory=list)   # (wall, sim) of each message

    def cpu_seconds(self) -> float:
        with open(f"/proc/{self.process.proc.pid}/stat") as f:
            fields = f.read().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / TICKS

    def on_clock(self, msg: Clock) -> None:
        self.clock.append((time.monotonic(), msg.clock.sec + msg.clock.nanosec * 1e-9))

    def arm(self, op: str) -> str:
        return f"{self.namespace}/acti_middle_node/{op}"

    def base(self, op: str) -> str:
        return f"{self.namespace}/vehicle_node/{op}"


def start(ros: RosClient, k: int, rate: float, log_dir: str) -> Robot:
    ns = f"/robot{k}"
    process = NodeProcess("acti_bringup", os.path.join(log_dir, f"robot{k}.log"),
                          f"rate_hz:={rate}", f"clock_rate_hz:={CLOCK_RATE_HZ}", namespace=ns)
    robot = Robot(ns, process)
    ros.node.create_subscription(Clock, f"{ns}/clock", robot.on_clock, 10)
    ros.call(srv.GetState, robot.arm("get_state"))        # waits until its services are up
    ros.call(srv.VehicleGetState, robot.base("get_state"))
    return robot


def set_moving(ros: RosClient, robot: Robot) -> None:
    """Queue MOVES arm swings and turn the base on the spot TURNS times; both outlast a window."""
    ros.call(srv.ServoON, robot.arm("servo_on"))
    ros.call(srv.SetSpeedJoint, robot.arm("set_speed_joint"), spd_ratio=30)
    ros.call(srv.VehicleSetPower, robot.base("set_power"), on_off=True)
    ros.call(srv.VehicleSetServo, robot.base("set_servo"), on_off=True)
    for i in range(MOVES):
        r = ros.call(srv.MovePTPJointAbs, robot.arm("move_ptp_joint_abs"),
                     joint_points=POSES[(i + 1) % 2])
        assert r.return_id.id == 0, r.return_id.comment
    b = ros.call(srv.VehicleMoveTurn, robot.base("move_turn"), theta=360.0 * TURNS)
    assert b.success, b.message


def stop(ros: RosClient, robot: Robot) -> None:
    ros.call(srv.Stop, robot.arm("stop"))
    ros.call(srv.VehicleStop, robot.base("stop"))


def at_rest(ros: RosClient, robot: Robot) -> bool:
    arm = ros.call(srv.GetState, robot.arm("get_state")).state
    base = ros.call(srv.VehicleGetState, robot.base("get_state")).state
    return not arm & 0x02 and base in (0x010, 0x019)      # not moving; Ready or Unpowered


def measure(ros: RosClient, robots: list[Robot], window: float) -> list[tuple[float, float]]:
    """(CPU % of one core, real-time factor) of each robot over `window` wall seconds."""
    settle = time.monotonic()
    ros.spin_until(lambda: time.monotonic() - settle >= SETTLE_S, SETTLE_S + 1.0)
    for r in robots:
        r.clock.clear()
    cpu0 = [r.cpu_seconds() for r in robots]
    t0, own0 = time.monotonic(), time.process_time()
    ros.spin_until(lambda: time.monotonic() - t0 >= window, window + 1.0)
    wall = time.monotonic() - t0
    for r in robots:
        if not r.process.alive():
            raise RuntimeError(f"{r.namespace} died:\n{r.process.log()[-2000:]}")
    print(f"   (the bench itself: {100.0 * (time.process_time() - own0) / wall:.1f} % of one core)")
    out = []
    for r, c0 in zip(robots, cpu0):
        cpu = 100.0 * (r.cpu_seconds() - c0) / wall
        rtf = 0.0
        if len(r.clock) >= 2:
            (w0, s0), (w1, s1) = r.clock[0], r.clock[-1]
            rtf = (s1 - s0) / (w1 - w0)
        out.append((cpu, rtf))
    return out


def summary(label: str, n: int, results: list[tuple[float, float]]) -> str:
    cpus, rtfs = [c for c, _ in results], [r for _, r in results]
    return (f"{n:2d} robots {label:6s}  CPU per robot mean {sum(cpus) / n:5.1f} % "
            f"max {max(cpus):5.1f} %  (all {sum(cpus):6.1f} % of one core)   "
            f"RTF min {min(rtfs):.3f} max {max(rtfs):.3f}")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--max", type=int, default=10, help="most robots to start")
    parser.add_argument("--window", type=float, default=10.0, help="seconds of each measurement")
    parser.add_argument("--rate", type=float, default=250.0, help="control rate of each robot [Hz]")
    args = parser.parse_args()
    ros = RosClient()
    robots: list[Robot] = []
    kept_up = 0
    print(f"{os.cpu_count()} cores; {args.rate:g} Hz per robot; windows of {args.window:g} s "
          f"after {SETTLE_S:g} s; real time = RTF 1 ± {REAL_TIME_TOLERANCE}")
    with tempfile.TemporaryDirectory() as log_dir:
        try:
            for n in range(1, args.max + 1):
                try:
                    robots.append(start(ros, n, args.rate, log_dir))
                except TimeoutError as e:        # the machine is full: this one never came up
                    print(f"robot {n} did not start: {e}", flush=True)
                    break
                wait_until(lambda: all(at_rest(ros, r) for r in robots), 30.0)
                idle = measure(ros, robots, args.window)
                print(summary("idle", n, idle), flush=True)
                for r in robots:
                    set_moving(ros, r)
                moving = measure(ros, robots, args.window)
                print(summary("moving", n, moving), flush=True)
                for r in robots:
                    stop(ros, r)
                if any(abs(rtf - 1.0) > REAL_TIME_TOLERANCE for _, rtf in idle + moving):
                    break
                kept_up = n
        finally:
            for r in robots:
                r.process.stop()
            ros.close()
    print(f"largest fleet in real time on this machine: {kept_up} robots")
    return 0


if __name__ == "__main__":
    sys.exit(main())
