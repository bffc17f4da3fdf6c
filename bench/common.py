"""Shared pieces of the benchmarks: DDS kept local, node processes, an honest latency method.

The method: one client node whose own cost stays flat over the run (`RosClient` waits with a
`spin_once` loop of its own; each table shows the p50 of the first and the last 10 % of its
calls), and the baseline interleaved with the measured calls (A B A B …), so that drift of the
machine or of the client cancels out of the ratios.
"""
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

from acti_bringup.harness import Actions, NodeProcess, RosClient  # noqa: E402
from bench.trigger_server import KIND as BARE_EXECUTOR  # noqa: E402

BARE = "/bare_trigger/trigger"
LOST_AFTER_S = 2.0   # a bare server's first answer not come by then was dropped (`answered`)


@contextmanager
def running(module: str, *params: str, args: tuple[str, ...] = ()) -> Iterator[NodeProcess]:
    with tempfile.TemporaryDirectory() as d:
        node = NodeProcess(module, os.path.join(d, "node.log"), *params, args=args)
        try:
            yield node
        finally:
            node.stop()


@contextmanager
def view_page(ros: RosClient, width: int, height: int, *params: str) -> Iterator[tuple]:
    """(job, browser): a main job (view on, any free port, `params`) with its live view open
    in a headless browser, the robot drawn and the page's notices dismissed."""
    import re

    from acti_bringup.harness import wait_until
    from acti_bringup.visual.browser import dismiss_notices, open_browser, robot_pixels, screenshot
    with running("acti_bringup", "view_port:=0", *params) as job:
        assert wait_until(lambda: "live view: " in job.log(), 60.0), job.log()
        url = re.search(r"live view: (\S+)", job.log()).group(1)
        browser = open_browser(width, height)
        try:
            browser.get(url)
            assert ros.spin_until(lambda: robot_pixels(screenshot(browser)).sum() > 300, 120.0), \
                "the page did not draw the robot"
            dismiss_notices(browser)
            yield job, browser
        finally:
            browser.quit()


def ok(reply) -> None:
    """An answer of either port that says OK (arm: return_id 0; base: success)."""
    status = getattr(reply, "return_id", None)
    assert (status.id == 0) if status is not None else reply.success, reply


def save_page(browser, out: str) -> None:
    """The page as the browser shows it, to a PNG."""
    import matplotlib.image as mpimg

    from acti_bringup.visual.browser import screenshot
    mpimg.imsave(out, screenshot(browser))


def bare_call(ros: RosClient) -> Callable[[], object]:
    from std_srvs.srv import Trigger
    return lambda: ros.call(Trigger, BARE)


def answered(ros: RosClient, srv_type: type, name: str, tries: int = 5, **fields: object) -> object:
    """The first call of a bare server just started, sent again while no answer comes within
    `LOST_AFTER_S`: rclpy's own send drops the response to a client whose reply reader the
    server has not discovered yet (ros2/ros2#1253; the nodes send it again,
    `acti_bringup.serving.responses`), and the call then waited for its whole timeout. For the
    bare servers only, whose calls change nothing."""
    timeout, ros.call_timeout = ros.call_timeout, LOST_AFTER_S
    try:
        for _ in range(tries - 1):
            try:
                return ros.call(srv_type, name, **fields)
            except TimeoutError:
                continue
    finally:
        ros.call_timeout = timeout
    return ros.call(srv_type, name, **fields)


def bare_trigger_answers(ros: RosClient) -> None:
    """`answered` for the bare Trigger server (`bench.trigger_server`) once it runs."""
    from std_srvs.srv import Trigger
    answered(ros, Trigger, BARE)


Calls = list[tuple[str, Callable[[], object]]]


def interleaved(calls: Calls, n: int, warmup: int = 30) -> dict[str, np.ndarray]:
    """Wall seconds of n rounds in which every call runs once, in the order given (A B A C …),
    after `warmup` rounds; a name listed twice (the baseline between each measured call) pools
    its samples."""
    for _ in range(warmup):
        for _name, fn in calls:
            fn()
    out: dict[str, list[float]] = {name: [] for name, _ in calls}
    for _ in range(n):
        for name, fn in calls:
            t0 = time.perf_counter()
            fn()
            out[name].append(time.perf_counter() - t0)
    return {name: np.array(sample) for name, sample in out.items()}


def latencies(fn: Callable[[], object], n: int, warmup: int = 30) -> np.ndarray:
    """Wall seconds of n calls of fn alone, after a warm-up (no baseline to interleave)."""
    return interleaved([("calls", fn)], n, warmup)["calls"]


def against(baseline: tuple[str, Callable[[], object]], measured: Calls) -> Calls:
    """The baseline call before each measured one: A B A C A D …"""
    return [c for m in measured for c in (baseline, m)]


Pairs = dict[str, tuple[np.ndarray, np.ndarray]]


def paired(baseline: Callable[[], object] | dict[str, Callable[[], object]], measured: Calls,
           n: int, warmup: int = 30, rounds: int = 1) -> Pairs:
    """Each measured call in blocks of its own, alternating with the baseline (A B A B …, then
    A C A C …), or with its own baseline where `baseline` maps each call's name to one:
    name -> (the baseline's samples, the call's samples) of its blocks. Both calls of
    a block are equally warm; in one round through many services (A B A C A D …) each service
    is called once in 2k calls and the baseline every other call, which weighs the caches'
    coldness (the client's as much as the server's) on the measured side only.

    With `rounds` > 1 the n alternations of each call are split into that many blocks, one per
    pass through all the calls, and pooled: the same call's ratio moved by ±0.07 from one block
    to the next (the machine as it was for those few seconds), so
    one block per call made the worst of many calls mostly the unluckiest block."""
    out: dict[str, tuple[list[np.ndarray], list[np.ndarray]]] = {name: ([], []) for name, _ in measured}
    for r in range(rounds):
        for name, fn in measured:
            base = baseline[name] if isinstance(baseline, dict) else baseline
            block = interleaved([("baseline", base), (name, fn)],
                                n // rounds + (r < n % rounds), warmup)
            out[name][0].append(block["baseline"])
            out[name][1].append(block[name])
    return {name: (np.concatenate(base), np.concatenate(sample))
            for name, (base, sample) in out.items()}


def p(sample: np.ndarray, q: float) -> float:
    """The q-th percentile in ms."""
    return float(np.percentile(sample, q)) * 1e3


def row(name: str, sample: np.ndarray, baseline: np.ndarray | None = None) -> str:
    """p50/p99, the ratios to the baseline, and the client's flatness (p50 of the first and the
    last 10 % of the calls)."""
    tenth = max(1, len(sample) // 10)
    text = (f"{name:<42} p50 {p(sample, 50):7.3f} ms  p99 {p(sample, 99):7.3f} ms"
            f"   first/last 10 % p50 {p(sample[:tenth], 50):6.3f} / {p(sample[-tenth:], 50):6.3f}")
    if baseline is not None:
        text += (f"   ratio p50 {p(sample, 50) / p(baseline, 50):5.2f}"
                 f"  p99 {p(sample, 99) / p(baseline, 99):5.2f}")
    return text


def table(title: str, pairs: Pairs, baseline: str, serves: str = "std_srvs/Trigger") -> None:
    """Print each measured call against the baseline samples of its own blocks (and the baseline's
    samples pooled); `serves`: what the bare server answers."""
    print(title)
    print(f"(bare baseline: {serves} on rclpy's {BARE_EXECUTOR} executor, the kind the "
          f"nodes' control plane runs on; client waits with its own spin_once loop; each call "
          f"in blocks of its own, alternating with the baseline)")
    print(row(baseline, np.concatenate([base for base, _ in pairs.values()])))
    for name, (base, sample) in pairs.items():
        print(row(name, sample, base))


def cpu_seconds(pid: int) -> float:
    """CPU time the process's threads have used so far, from the scheduler's nanosecond
    counters (`/proc/<pid>/task/*/schedstat`): `/proc/<pid>/stat` counts clock ticks (10 ms),
    which made a 200-call figure a multiple of 50 µs. A thread that ended takes its time along."""
    total = 0
    for task in os.listdir(f"/proc/{pid}/task"):
        try:
            with open(f"/proc/{pid}/task/{task}/schedstat") as f:
                total += int(f.read().split()[0])
        except (FileNotFoundError, ProcessLookupError):   # the thread ended meanwhile
            pass
    return total * 1e-9


def idle_cpu_percent(pid: int, seconds: float = 5.0) -> float:
    """Share of one core a process uses over `seconds` of wall time."""
    c0, t0 = cpu_seconds(pid), time.monotonic()
    time.sleep(seconds)   # the measurement window itself
    return 100.0 * (cpu_seconds(pid) - c0) / (time.monotonic() - t0)


def worst_ratios(pairs: Pairs) -> tuple[float, float]:
    """The largest p50 and p99 ratio of any measured call to its block's baseline."""
    return (max(p(s, 50) / p(base, 50) for base, s in pairs.values()),
            max(p(s, 99) / p(base, 99) for base, s in pairs.values()))


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


def simulated_base(velocity: tuple[float, float] | None = None,
                   acceleration: tuple[float, float] | None = None):
    """(world, executor, vehicle core) free-running, powered, servo on, with these settings
    (None: the start-up ones)."""
    from acti_motion.executor import MotionExecutor
    from acti_motion.vehicle.core import VehicleCore
    from acti_sim.world import World
    world = World()
    executor = MotionExecutor(world, real_time_factor=0.0)
    base = VehicleCore(executor)
    base.set_power(True)
    base.set_servo(True)
    if velocity is not None:
        base.set_velocity(velocity)
    if acceleration is not None:
        base.set_acceleration(acceleration)
    return world, executor, base


__all__ = ["Actions", "RosClient", "running", "bare_call", "answered", "bare_trigger_answers", "interleaved", "latencies", "against",
           "row", "table", "p", "worst_ratios", "idle_cpu_percent", "simulated_arm", "simulated_base"]
