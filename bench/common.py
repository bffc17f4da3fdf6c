"""Shared pieces of the benchmarks: DDS kept local, node processes, latency statistics."""
from __future__ import annotations

import os
import sys
import tempfile
import time
from contextlib import contextmanager
from typing import Callable, Iterator

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
os.environ.setdefault("ROS_DOMAIN_ID", str(101 + os.getpid() % 60))
os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
os.environ["FASTDDS_BUILTIN_TRANSPORTS"] = "UDPv4"

from acti_bringup.harness import NodeProcess, RosClient  # noqa: E402


@contextmanager
def running(module: str, *params: str) -> Iterator[NodeProcess]:
    with tempfile.TemporaryDirectory() as d:
        node = NodeProcess(module, os.path.join(d, "node.log"), *params)
        try:
            yield node
        finally:
            node.stop()


def latencies(fn: Callable[[], object], n: int, warmup: int = 30) -> np.ndarray:
    """Wall seconds of n calls of fn after a warm-up."""
    for _ in range(warmup):
        fn()
    out = np.empty(n)
    for i in range(n):
        t0 = time.perf_counter()
        fn()
        out[i] = time.perf_counter() - t0
    return out


def row(name: str, sample: np.ndarray, baseline: np.ndarray | None = None) -> str:
    p50, p99 = np.percentile(sample, 50) * 1e3, np.percentile(sample, 99) * 1e3
    text = f"{name:<34} p50 {p50:7.3f} ms   p99 {p99:7.3f} ms"
    if baseline is not None:
        b50, b99 = np.percentile(baseline, 50) * 1e3, np.percentile(baseline, 99) * 1e3
        text += f"   ratio p50 {p50 / b50:5.2f}  p99 {p99 / b99:5.2f}"
    return text


def simulated_arm(initial_joints_deg: tuple[float, ...], speed: int):
    """(world, executor, arm core) free-running, servo on, both speed ratios at `speed` %."""
    from acti_motion.arm.core import ArmConfig, ArmCore
    from acti_motion.executor import MotionExecutor
    from acti_sim.world import World
    world = World()
    executor = MotionExecutor(world, real_time_factor=0.0)
    arm = ArmCore(executor, ArmConfig(initial_joints_deg=initial_joints_deg))
    arm.servo_on()
    arm.set_speed_joint(speed)
    arm.set_speed_cartesian(speed)
    return world, executor, arm


def simulated_base(velocity: tuple[float, float], acceleration: tuple[float, float]):
    """(world, executor, vehicle core) free-running, powered, servo on, with these settings."""
    from acti_motion.executor import MotionExecutor
    from acti_motion.vehicle.core import VehicleCore
    from acti_sim.world import World
    world = World()
    executor = MotionExecutor(world, real_time_factor=0.0)
    base = VehicleCore(executor)
    base.set_power(True)
    base.set_servo(True)
    base.set_velocity(velocity)
    base.set_acceleration(acceleration)
    return world, executor, base


__all__ = ["RosClient", "running", "latencies", "row", "simulated_arm", "simulated_base"]
