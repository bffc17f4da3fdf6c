"""Reindexing a recording a kill cut short (`python -m acti_bringup.reindex`): its wall time
for a file of joint states, beside two baselines measured in the same run on the same cut file:
reading it record by record (`read_recording`, what every reader here does) and copying its
bytes (the disk's floor). Figures, no assertions.

    python bench/bench_reindex.py [messages] [repeats]
"""
from __future__ import annotations

import os
import shutil
import statistics
import sys
import tempfile
import time
from typing import Callable

from rclpy.serialization import serialize_message
from sensor_msgs.msg import JointState

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)

from acti_bringup.recording.types import share_dir  # noqa: E402
from acti_record.definitions import full_text  # noqa: E402
from acti_record.reading import read_recording  # noqa: E402
from acti_record.reindexing import reindex_file  # noqa: E402
from acti_record.writing import McapFile, Topic  # noqa: E402

JOINTS = [f"joint{i}" for i in range(1, 8)]


def cut_recording(path: str, messages: int) -> None:
    """`messages` joint states at 250 Hz in a file whose last 1,000 bytes a kill cut off."""
    topic = Topic("/joint_states", "sensor_msgs/msg/JointState",
                  full_text("sensor_msgs/msg/JointState", share_dir))
    file = McapFile(path + ".whole")
    for i in range(messages):
        state = JointState(name=JOINTS, position=[i * 1e-4 + j for j in range(7)],
                           velocity=[0.1] * 7, effort=[0.0] * 7)
        state.header.stamp.sec, state.header.stamp.nanosec = divmod(i * 4_000_000, 10**9)
        file.write(topic, serialize_message(state), i * 4_000_000, i * 4_000_000)
    file.close()
    with open(path + ".whole", "rb") as src, open(path + ".cut", "wb") as dst:
        dst.write(src.read(os.path.getsize(path + ".whole") - 1_000))


def timed(prepare: Callable[[], None], run: Callable[[], object], repeats: int) -> float:
    """The median wall seconds of `run`, each after `prepare` (not timed)."""
    samples = []
    for _ in range(repeats):
        prepare()
        t0 = time.perf_counter()
        run()
        samples.append(time.perf_counter() - t0)
    return statistics.median(samples)


def main() -> None:
    messages = int(sys.argv[1]) if len(sys.argv) > 1 else 100_000
    repeats = int(sys.argv[2]) if len(sys.argv) > 2 else 5
    with tempfile.TemporaryDirectory() as folder:
        base = os.path.join(folder, "session")
        cut_recording(base, messages)
        path, size = base + ".mcap", os.path.getsize(base + ".cut")
        fresh = lambda: shutil.copyfile(base + ".cut", path)        # noqa: E731
        copy = timed(lambda: None, lambda: shutil.copyfile(base + ".cut", path), repeats)
        read = timed(fresh, lambda: read_recording(path), repeats)
        reindex = timed(fresh, lambda: reindex_file(path), repeats)
    print(f"a cut file of {messages:,} joint states, {size / 1e6:.1f} MB (median of {repeats}):")
    for name, seconds in (("copy its bytes", copy), ("read it record by record", read),
                          ("reindex it", reindex)):
        print(f"  {name:<26} {seconds:6.3f} s  {size / 1e6 / seconds:7.1f} MB/s  "
              f"{seconds / read:5.2f} x the read")


if __name__ == "__main__":
    main()
