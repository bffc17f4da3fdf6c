"""The live view must not slow the simulation: the main job's real-time factor (free-running,
real_time_factor:=0) and CPU (paced at real time) with the view off, on with no page open, and on
with one headless Chromium showing the page, interleaved round by round. The arm moves the whole
time (a slow joint move), so the view streams poses. Prints figures only.

    python bench/bench_view.py [ROUNDS]
"""
from __future__ import annotations

import os
import re
import sys
import time

import numpy as np
from common import RosClient, running

from acti_bringup.visual.browser import open_browser
from acti_msgs import srv
from acti_msgs.msg import ArmState

ARM = "/acti_middle_node/"
WARMUP_S = 4.0
WINDOW_S = 10.0
MODES = ("view off", "view on, no page", "view on, one page")
CLOCK_TICKS = os.sysconf("SC_CLK_TCK")


def cpu_seconds(pid: int) -> float:
    """User + system CPU time of a process and its threads so far."""
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / CLOCK_TICKS


def measure(ros: RosClient, mode: str, real_time_factor: float) -> tuple[float, float]:
    """(real-time factor, CPU in % of one core) of the main job over the window."""
    params = [f"real_time_factor:={real_time_factor}", "view_port:=0",
              f"view_enabled:={'false' if mode == 'view off' else 'true'}"]
    stamps: list[tuple[float, float]] = []

    def on_state(msg: ArmState) -> None:
        stamps.append((time.monotonic(), msg.stamp.sec + 1e-9 * msg.stamp.nanosec))
    sub = ros.node.create_subscription(ArmState, ARM + "state", on_state, 10)
    browser = None
    try:
        with running("acti_bringup", *params) as job:
            ros.call(srv.ServoON, ARM + "servo_on")
            ros.call(srv.SetSpeedJoint, ARM + "set_speed_joint", spd_ratio=1)
            for j1 in (150.0, -150.0) * 3:     # back and forth: moving for the whole window,
                r = ros.call(srv.MovePTPJointRel, ARM + "move_ptp_joint_rel",   # free-running too
                             joint_points=[j1, 0, 0, 0, 0, 0, 0])
                assert r.return_id.id == 0, r.return_id.comment
            if mode == "view on, one page":
                url = re.search(r"live view: (\S+)", job.log()).group(1)
                browser = open_browser(800, 500)
                browser.get(url)
            ros.spin_until(lambda: False, WARMUP_S)
            stamps.clear()
            cpu0, wall0 = cpu_seconds(job.proc.pid), time.monotonic()
            ros.spin_until(lambda: False, WINDOW_S)
            cpu = (cpu_seconds(job.proc.pid) - cpu0) / (time.monotonic() - wall0)
            moving = ros.call(srv.GetState, ARM + "get_state").state & 0x02
            assert moving, "the arm stopped moving during the window"
    finally:
        if browser is not None:
            browser.quit()
        ros.node.destroy_subscription(sub)
    (w0, s0), (w1, s1) = stamps[0], stamps[-1]
    return (s1 - s0) / (w1 - w0), 100.0 * cpu


def main() -> None:
    rounds = int(sys.argv[1]) if len(sys.argv) > 1 else 3
    ros = RosClient()
    rtf = {m: [] for m in MODES}
    cpu = {m: [] for m in MODES}
    for r in range(rounds):
        for mode in MODES:
            free, free_cpu = measure(ros, mode, 0.0)
            rtf[mode].append(free)
            cpu[mode].append(measure(ros, mode, 1.0)[1])
            # the free-running job's own CPU tells a slower simulation (the job starved of CPU
            # by the browser's software WebGL on this machine) from a view that slows it
            print(f"  round {r + 1}: {mode:<18} free-running RTF {free:6.2f} (job CPU "
                  f"{free_cpu:5.1f} %)   CPU at 1x {cpu[mode][-1]:5.1f} %", flush=True)
    ros.close()
    print(f"\nlive view cost ({rounds} interleaved rounds, median; arm moving; "
          f"{os.cpu_count()} cores)")
    base_rtf, base_cpu = np.median(rtf[MODES[0]]), np.median(cpu[MODES[0]])
    for mode in MODES:
        print(f"  {mode:<18} free-running real-time factor {np.median(rtf[mode]):6.2f} "
              f"({np.median(rtf[mode]) / base_rtf:5.2f} of view off)   "
              f"main job CPU at 1x {np.median(cpu[mode]):5.1f} % "
              f"({np.median(cpu[mode]) - base_cpu:+4.1f} points)")


if __name__ == "__main__":
    main()
