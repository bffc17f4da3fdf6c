"""What recording costs: the main job at real time (real_time_factor 1.0) with both devices
moving, its real-time factor (simulated seconds per wall second, read off /clock) and CPU while
`python -m acti_bringup.record` records every topic, against the same run without a recorder,
in windows interleaved (off, on, off, on …); the recorder's CPU and what it wrote. Goal: the job
keeps a real-time factor >= 1.0 while recorded. Then the same as fast as the job can
(real_time_factor 0), and the control plane's price of service introspection: the get_state
round trip of a job with `service_introspection` contents against one with it disabled, both
running, the calls interleaved."""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import tempfile
import time

import numpy as np
from acti_msgs import srv
from bench_ros_graph import measure
from common import NodeProcess, RosClient, cpu_seconds, paired, running, row

from acti_bringup.harness import (ARM, ROOT, both_moving, keep_moving, start_moving,
                                  stop_moving)

WINDOWS = 4                      # of each kind, interleaved
QUEUED = 24                      # motions per device queued for each window


def windows(ros: RosClient, job_pid: int, folder: str) -> dict[str, list[tuple]]:
    """(RTF, job CPU, recorder CPU, bytes/s) of each window, by kind."""
    out: dict[str, list[tuple]] = {"not recorded": [], "recorded": []}
    for w in range(2 * WINDOWS):
        recorded = w % 2 == 1
        recorder, path = None, os.path.join(folder, f"w{w}.mcap")
        if recorded:
            recorder = subprocess.Popen([sys.executable, "-m", "acti_bringup.record", path],
                                        cwd=ROOT, stdout=subprocess.DEVNULL,
                                        stderr=subprocess.DEVNULL)
            deadline = time.monotonic() + 30
            while (not os.path.exists(path) or os.path.getsize(path) < 300_000) \
                    and time.monotonic() < deadline:
                time.sleep(0.1)               # subscribed to everything and writing
        stop_moving(ros)
        keep_moving(ros, QUEUED)
        if recorder is not None:
            r0, s0 = cpu_seconds(recorder.pid), os.path.getsize(path)
        t0 = time.monotonic()
        rtf, cpu = measure(ros, job_pid)
        seconds = time.monotonic() - t0
        rec_cpu = rate = 0.0
        if recorder is not None:
            rec_cpu = (cpu_seconds(recorder.pid) - r0) / seconds
            rate = (os.path.getsize(path) - s0) / seconds
            recorder.send_signal(signal.SIGINT)
            recorder.wait(timeout=30)
        moving = both_moving(ros)
        out["recorded" if recorded else "not recorded"].append((rtf, cpu, rec_cpu, rate, moving))
    stop_moving(ros)
    return out


def report(title: str, out: dict[str, list[tuple]]) -> None:
    print(title)
    for kind, rows in out.items():
        a = np.array(rows)
        print(f"  {kind:<13} RTF {a[:, 0].mean():.3f} (min {a[:, 0].min():.3f})  job CPU "
              f"{100 * a[:, 1].mean():4.0f} %  recorder CPU {100 * a[:, 2].mean():4.0f} %  "
              f"written {a[:, 3].mean() / 1e6:5.2f} MB/s  both moving at the end of "
              f"{int(a[:, 4].astype(bool).sum())}/{len(a)} windows")
    on, off = (np.array(out[k])[:, 0].mean() for k in ("recorded", "not recorded"))
    print(f"  RTF recorded / not recorded: {on / off:.3f}")


def introspection_cost(ros: RosClient) -> None:
    with tempfile.TemporaryDirectory() as folder:
        jobs = [NodeProcess("acti_bringup", os.path.join(folder, f"{state}.log"),
                            "real_time_factor:=1.0", "view_enabled:=false",
                            f"service_introspection:={state}", namespace=f"/{state}")
                for state in ("disabled", "contents")]
        try:
            calls = {j: (lambda n=j: ros.call(srv.GetState, f"/{n}{ARM}get_state"))
                     for j in ("disabled", "contents")}
            pairs = paired(calls["disabled"], [("contents", calls["contents"])], n=600, rounds=3)
        finally:
            for job in jobs:
                job.stop()
    base, sample = pairs["contents"]
    print("get_state round trip, service_introspection contents against disabled (both jobs "
          "running, calls interleaved)")
    print(row("introspection disabled", base))
    print(row("introspection contents", sample, base))


def main() -> None:
    ros = RosClient()
    try:
        with tempfile.TemporaryDirectory() as folder:
            for factor in ("1.0", "0.0"):
                with running("acti_bringup", f"real_time_factor:={factor}") as job:
                    start_moving(ros)
                    report(f"main job at real_time_factor {factor}, arm and base moving, "
                           f"{WINDOWS} windows of each kind interleaved",
                           windows(ros, job.proc.pid, folder))
        introspection_cost(ros)
    finally:
        ros.close()


if __name__ == "__main__":
    main()
