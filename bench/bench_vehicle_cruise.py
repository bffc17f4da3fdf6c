"""moveCruiseAbs against the time-optimal bound: the same path (spline through the points) and
limits, timed by TOPP-RA on a fine grid. Simulated seconds; no ROS (the core on its own world).
Then the planning cost of adding points one by one (wall time per call, first and last tenth):
flat when adding a point costs the same however many came before. Last, set_velocity
re-plans beside the simulation step, planned here and in the planning process (`--replan`:
only that part)."""
from __future__ import annotations

import math
import os
import sys
import threading
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from common import simulated_base  # noqa: E402

from acti_motion.executor import MotionExecutor  # noqa: E402
from acti_motion.vehicle.core import VehicleCore  # noqa: E402
from acti_motion.vehicle.paths import Pose2D  # noqa: E402
from acti_sim.world import World  # noqa: E402
from acti_motion.vehicle.cruise import plan_curve, spline_through, time_optimal  # noqa: E402

POINTS_MM = [(1000.0, 0.0), (2000.0, 600.0), (3000.0, 0.0), (4000.0, 600.0), (5000.0, 0.0)]
SETTINGS = ((800.0, 90.0), (500.0, 180.0))          # velocity, acceleration (mm, degree)


def main() -> None:
    world, executor, base = simulated_base(*SETTINGS)
    wall = []
    for p in POINTS_MM:
        t0 = time.perf_counter()
        base.move_cruise_abs(p)
        wall.append(time.perf_counter() - t0)
    motion = base.device.queue[0].motion
    planned = motion.path.duration
    t0, within, closest, slowest = world.time, None, {p: math.inf for p in POINTS_MM}, math.inf
    last = POINTS_MM[-1]
    while base.device.busy:
        executor.step()
        pose = base.odometry.pose
        here = (1000.0 * pose.x, 1000.0 * pose.y)
        for p in POINTS_MM:
            closest[p] = min(closest[p], math.dist(here, p))
        if within is None and math.dist(here, last) < 5.0 and abs(base.odometry.v) < 0.01:
            within = world.time - t0
        if closest[POINTS_MM[0]] < 10.0 and math.dist(here, last) > 100.0:
            slowest = min(slowest, base.odometry.v)
    done = world.time - t0

    limits = (SETTINGS[0][0] / 1000.0, math.radians(SETTINGS[0][1]),
              SETTINGS[1][0] / 1000.0, math.radians(SETTINGS[1][1]))
    points = [(x / 1000.0, y / 1000.0) for x, y in POINTS_MM]
    s, _, _, heading, _ = spline_through(Pose2D(0.0, 0.0, 0.0), points)
    bound = time_optimal(s, heading, limits, grid_step=0.001, grid_max=20000).duration
    check = plan_curve(Pose2D(0.0, 0.0, 0.0), points, limits).path.duration
    world.close()

    print(f"cruise through {len(POINTS_MM)} points, {s[-1]:.2f} m of path; limits v {SETTINGS[0][0]:g} mm/s, "
          f"w {SETTINGS[0][1]:g} deg/s, a {SETTINGS[1][0]:g} mm/s2, alpha {SETTINGS[1][1]:g} deg/s2")
    print(f"  time-optimal bound (TOPP-RA, 1 mm grid)   {bound:7.3f} s")
    print(f"  planned (TOPP-RA ConstAccel, 1 cm grid)   {planned:7.3f} s   ratio {planned / bound:6.4f}"
          f"   (same plan again: {check:.3f} s)")
    print(f"  executed, at rest within 5 mm of the end  {within:7.3f} s   ratio {within / bound:6.4f}")
    print(f"  executed, motion done (incl. 0.4 s settle) {done:6.3f} s")
    print(f"  slowest between the first point and 100 mm before the last: {1000.0 * slowest:.0f} mm/s")
    print("  closest approach to each point (mm): " + ", ".join(f"{closest[p]:.2f}" for p in POINTS_MM))
    print(f"  planning per move_cruise_abs call (wall): mean {1000 * sum(wall) / len(wall):.1f} ms, "
          f"max {1000 * max(wall):.1f} ms (toppra is imported and warmed up at start-up)")


def adding_points(n: int) -> None:
    """Wall time of each of n move_cruise_abs calls on a queued cruise (a zig-zag, 0.4 m apart)."""
    world, _, base = simulated_base()
    wall = []
    for i in range(n):
        t0 = time.perf_counter()
        assert base.move_cruise_abs((400.0 * (i + 1), 300.0 * (i % 2))).ok
        wall.append(time.perf_counter() - t0)
    world.close()
    tenth = max(1, n // 10)
    first, last = sorted(wall[:tenth]), sorted(wall[-tenth:])
    print(f"  {n:4d} points added one by one: total {sum(wall):6.2f} s; per call p50 first tenth "
          f"{1000 * first[len(first) // 2]:6.1f} ms, last tenth {1000 * last[len(last) // 2]:6.1f} ms, "
          f"max {1000 * max(wall):6.1f} ms")


def stepping_base() -> tuple[World, MotionExecutor, VehicleCore, list[float]]:
    """A base, powered with the servo on, stepped in real time on the executor's own thread;
    the list fills with the wall time (perf_counter) of every step."""
    world = World()
    executor = MotionExecutor(world, real_time_factor=1.0)
    base = VehicleCore(executor)
    steps: list[float] = []
    executor.after_step(lambda _: steps.append(time.perf_counter()))
    executor.start()
    base.set_power(True)
    base.set_servo(True)
    return world, executor, base, steps


def stop_while_planning(trials: int = 20) -> None:
    """The core's control plane while another thread plans: a cruise runs (the simulation on its
    own thread, real time), a thread adds a far cruise point (a long re-plan), and stop is called
    as that plan starts. Wall time of stop and of get_state, and the largest gap between two
    simulation steps meanwhile, against the control period."""
    world, executor, base, steps = stepping_base()
    stops, states, gaps, plans = [], [], [], []
    try:
        for _ in range(trials):
            base.set_position((0.0, 0.0, 0.0))
            base.move_cruise_abs((3000.0, 500.0))
            while base.odometry.v < 0.2:
                time.sleep(0.005)

            def add() -> None:
                t0 = time.perf_counter()
                base.move_cruise_abs((90000.0, 90000.0))
                plans.append(time.perf_counter() - t0)
            planner = threading.Thread(target=add)
            steps.clear()
            planner.start()
            time.sleep(0.005)
            t0 = time.perf_counter()
            base.get_state()
            states.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            base.stop()
            stops.append(time.perf_counter() - t0)
            planner.join()
            gaps.append(max(b - a for a, b in zip(steps, steps[1:])) if len(steps) > 1 else 0.0)
            while base.device.busy:
                time.sleep(0.01)
    finally:
        executor.shutdown()
        world.close()

    def pct(values: list[float], q: float) -> float:
        return sorted(values)[min(len(values) - 1, int(q * len(values)))] * 1000.0
    print(f"control plane while another thread plans (ROS-free core, {trials} trials; "
          f"control period {1000 * executor.dt:.2f} ms):")
    print(f"  concurrent plan (wall) p50 {pct(plans, 0.5):.1f} ms, max {pct(plans, 1.0):.1f} ms")
    print(f"  stop      p50 {pct(stops, 0.5):.3f} ms, p99 {pct(stops, 0.99):.3f} ms, max {pct(stops, 1.0):.3f} ms")
    print(f"  get_state p50 {pct(states, 0.5):.3f} ms, p99 {pct(states, 0.99):.3f} ms, max {pct(states, 1.0):.3f} ms")
    print(f"  largest gap between simulation steps: p50 {pct(gaps, 0.5):.1f} ms, max {pct(gaps, 1.0):.1f} ms")


def replanning_beside_the_step(rounds: int = 6, seconds: float = 2.0) -> None:
    """set_velocity re-plans a running cruise (8 points, 4.8 m) back to back for `seconds`,
    with the plans in this process (as before) and in the planning process (acti_motion.vehicle
    .planner), interleaved with rounds that only cruise (the baseline). Per mode: this
    process's CPU per re-plan (the calling thread's: what holds the GIL the simulation step
    needs), the answer's wall time, and the largest gap between two simulation steps (real
    time: one step is 4.17 ms) per round."""
    from acti_motion.vehicle import planner
    world, executor, base, stamps = stepping_base()
    figures: dict[str, tuple[list[float], list[float], list[float]]] = {}
    try:
        for _ in range(rounds):
            for mode in ("cruise only", "plans here", "plans in the planning process"):
                if mode.endswith("process"):
                    planner.start()
                    planner.wait_ready()
                cpu, wall, gaps = figures.setdefault(mode, ([], [], []))
                base.set_position((0.0, 0.0, 0.0))
                base.set_velocity((600.0, 60.0))
                for i in range(8):
                    base.move_cruise_abs((600.0 * (i + 1), 400.0 * (i % 2)))
                while base.odometry.v < 0.3:
                    time.sleep(0.005)
                stamps.clear()
                end, k = time.perf_counter() + seconds, 0
                while time.perf_counter() < end:
                    if mode == "cruise only":
                        time.sleep(0.05)
                        continue
                    c0, t0 = time.thread_time(), time.perf_counter()
                    base.set_velocity((400.0 if k % 2 else 600.0, 60.0))
                    wall.append(time.perf_counter() - t0)
                    cpu.append(time.thread_time() - c0)
                    k += 1
                gaps.append(max(b - a for a, b in zip(stamps, stamps[1:])))
                base.stop()
                while base.device.busy:
                    time.sleep(0.01)
                planner.stop()
    finally:
        executor.shutdown()
        world.close()
    print(f"set_velocity re-plans of a running cruise, back to back ({rounds} interleaved rounds "
          f"of {seconds:g} s per mode; control period {1000 * executor.dt:.2f} ms):")
    for mode, (cpu, wall, gaps) in figures.items():
        ms = lambda v, q: 1000.0 * float(np.quantile(v, q))  # noqa: E731
        plans = (f"this process's CPU per re-plan p50 {ms(cpu, 0.5):6.1f} ms; answer p50 "
                 f"{ms(wall, 0.5):6.1f} ms, max {ms(wall, 1.0):6.1f} ms; " if cpu else "")
        print(f"  {mode:30s} {plans}largest step gap per round: p50 {ms(gaps, 0.5):5.1f} ms, "
              f"max {ms(gaps, 1.0):5.1f} ms")


if __name__ == "__main__" and sys.argv[1:] == ["--replan"]:
    replanning_beside_the_step()          # only this part (python bench/bench_vehicle_cruise.py --replan)
elif __name__ == "__main__":
    main()
    print("planning cost of cruise points added one by one (a queued cruise; wall time):")
    for count in (10, 50, 200):
        adding_points(count)
    stop_while_planning()
    replanning_beside_the_step()
