"""What the ROS-graph topics cost the simulation: the main job run as fast as it can
(real_time_factor 0), its real-time factor read off /clock, and at real time (1.0) its CPU use
and the `get_state` round trip (p99: the control plane must not wait for a frame), with the
links' TF off and on and the camera off and on (two sizes, two rates). CPU counts the render
process too."""
from __future__ import annotations

import os
import time

import numpy as np
from acti_msgs.srv import GetState
from common import RosClient, latencies, running

from rosgraph_msgs.msg import Clock
from rclpy.qos import QoSProfile

WINDOW_S = 8.0
CASES = [
    ("no link TF, no camera", ["link_tf:=false"]),
    ("link TF (default)", []),
    ("link TF + camera 320×240 at 2 Hz", ["camera_rate_hz:=2.0"]),
    ("link TF + camera 320×240 at 10 Hz", ["camera_rate_hz:=10.0"]),
    ("link TF + camera 640×480 at 5 Hz", ["camera_rate_hz:=5.0", "camera_width:=640",
                                         "camera_height:=480"]),
]


def _stat(pid: str) -> list[str]:
    with open(f"/proc/{pid}/stat") as f:
        return f.read().rsplit(")", 1)[1].split()


def cpu_seconds(pid: int) -> float:
    """CPU time of the process and its children (the camera's render process)."""
    total = 0
    for p in os.listdir("/proc"):
        try:
            fields = _stat(p) if p.isdigit() else None
        except OSError:
            continue
        if fields and (p == str(pid) or fields[1] == str(pid)):
            total += int(fields[11]) + int(fields[12])
    return total / os.sysconf("SC_CLK_TCK")


def measure(ros: RosClient, pid: int) -> tuple[float, float]:
    """(simulated seconds per wall second, CPU fraction of one core) over WINDOW_S."""
    latest: list[Clock] = []
    sub = ros.node.create_subscription(Clock, "/clock", lambda m: latest.append(m),
                                       QoSProfile(depth=1))
    try:
        if not ros.spin_until(lambda: latest, 30.0):
            raise TimeoutError("no /clock")
        ros.spin_until(lambda: False, 2.0)                       # start-up over
        t0, c0, s0 = time.monotonic(), cpu_seconds(pid), latest[-1].clock
        ros.spin_until(lambda: False, WINDOW_S)
        t1, c1, s1 = time.monotonic(), cpu_seconds(pid), latest[-1].clock
    finally:
        ros.node.destroy_subscription(sub)
    sim = (s1.sec - s0.sec) + (s1.nanosec - s0.nanosec) * 1e-9
    return sim / (t1 - t0), (c1 - c0) / (t1 - t0)


def main() -> None:
    ros = RosClient()
    try:
        print(f"{'case':<36} {'RTF, as fast as it can':>24} {'at real time: CPU':>18}"
              f" {'get_state p50 / p99':>22}")
        for name, params in CASES:
            with running("acti_bringup", "real_time_factor:=0.0", *params) as node:
                fastest, _ = measure(ros, node.proc.pid)
            with running("acti_bringup", "real_time_factor:=1.0", *params) as node:
                rtf, cpu = measure(ros, node.proc.pid)
                trips = latencies(lambda: ros.call(GetState, "/acti_middle_node/get_state"), 300)
            p50, p99 = np.percentile(trips, [50, 99]) * 1e3
            print(f"{name:<36} {fastest:>22.2f} × {100 * cpu:>15.0f} %"
                  f" {p50:>10.1f} / {p99:5.1f} ms   (RTF {rtf:.3f})")
    finally:
        ros.close()


if __name__ == "__main__":
    main()
