"""Arm figures: move accept latency while moving (over DDS), PTP duration vs the analytic
trapezoid, CP duration vs the TOPP-RA time-optimal bound, tracking in the simulation.
Prints figures only (no timing asserts). The node runs as `bench.timed_node` (acti_middle_node
with its move callbacks timed), so that the handler's own cost is printed beside the round trip's."""
import json
import math
import os
import shutil
import tempfile
import time
from contextlib import contextmanager
from typing import Iterator

import numpy as np
from common import (RosClient, answered, bare_call, bare_trigger_answers, cpu_seconds, paired,
                    running, simulated_arm, table)

from bench.clock_floor import NICENESS
from bench.trigger_server import REPLAY

from acti_msgs import srv
from acti_msgs.msg import CarPosWithElbow

N = 800           # p99 is then the 8th largest of a call's samples, not the 2nd
BLOCKS = 8        # the N alternations of a call: in this many blocks, spread over the run
IDENTITY = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0]
ARM = "/acti_middle_node/"
ARM_START = (0.0, 45.0, 0.0, -90.0, 0.0, 45.0, 0.0)
CPU_CALLS = 200   # accepts in a row whose CPU in the node is summed
WARMUP = 10       # calls of each block before its measured ones
IDLE_CALLS = N + WARMUP * BLOCKS     # the idle arm's accepts (`idle_accepts`)


def accept_latency() -> None:
    ros = RosClient()
    handlers = os.path.join(tempfile.mkdtemp(), "handlers.json")   # bench.timed_node's
    with running("bench.trigger_server"), \
            running("bench.timed_node", "queue_size:=5000", args=(handlers,)) as node:
        bare_trigger_answers(ros)
        ros.call(srv.ServoON, ARM + "servo_on")
        ros.call(srv.SetSpeedJoint, ARM + "set_speed_joint", spd_ratio=5)
        ros.call(srv.SetSpeedCartesian, ARM + "set_speed_cartesian", spd_ratio=5)
        # a long first move keeps the arm moving while the others queue behind it
        ros.call(srv.MovePTPJointRel, ARM + "move_ptp_joint_rel", joint_points=[60.0] + [0.0] * 6)
        ros.spin_until(lambda: ros.call(srv.GetState, ARM + "get_state").state & 0x02, 5.0)
        sign: dict[str, float] = {}     # each kind, on each server, goes back and forth: no drift

        def flip(key: str) -> float:
            sign[key] = -sign.get(key, -1.0)
            return sign[key]

        def ptp(prefix: str = "") -> None:
            r = ros.call(srv.MovePTPJointRel, prefix + ARM + "move_ptp_joint_rel",
                         joint_points=[0.5 * flip("ptp" + prefix)] * 7)
            assert r.return_id.id == 0, r.return_id.comment

        def cp(prefix: str = "") -> None:
            m = list(IDENTITY)
            m[3] = 20.0 * flip("cp" + prefix)
            r = ros.call(srv.MoveLinearCartesianRel, prefix + ARM + "move_linear_cartesian_rel",
                         car_point=CarPosWithElbow(car_pos=m))
            assert r.return_id.id == 0, r.return_id.comment

        def state(prefix: str = "") -> None:
            ros.call(srv.GetState, prefix + ARM + "get_state")
        calls = {"get_state while moving": state, "move_ptp_joint_rel accept": ptp,
                 "move_linear_cartesian_rel (20 mm) accept": cp}
        pairs = paired(bare_call(ros), list(calls.items()), N, warmup=WARMUP, rounds=BLOCKS)
        replayed = {"get_state": (srv.GetState, {}),          # each with a call that moves nothing
                    "move_ptp_joint_rel": (srv.MovePTPJointRel, {"joint_points": [0.0] * 7}),
                    "move_linear_cartesian_rel": (srv.MoveLinearCartesianRel,
                                                  {"car_point": CarPosWithElbow(car_pos=IDENTITY)})}
        moves = [(name, fn) for name, fn in calls.items() if name != "get_state while moving"]
        with replay_server(ros, replayed):
            same = paired({name: lambda fn=fn: fn(REPLAY) for name, fn in calls.items()},
                          list(calls.items()), N, warmup=WARMUP, rounds=BLOCKS)
            cpu = {name: planning_cpu(node.proc.pid, fn) for name, fn in moves}
            moving = ros.call(srv.GetState, ARM + "get_state").state & 0x02
            same.update(idle_accepts(ros))
        with replay_server(ros, replayed, f"--nice={NICENESS}"):
            ranked = paired({name: lambda fn=fn: fn(REPLAY) for name, fn in moves}, moves, N,
                            warmup=WARMUP, rounds=BLOCKS)

    with open(handlers) as f:                      # written as the node ended
        handler_times = json.load(f)
    shutil.rmtree(os.path.dirname(handlers))
    table(f"round trip over DDS, {N} alternations (bare, call) for each call in {BLOCKS} blocks "
          f"spread over the run, arm moving: {bool(moving)} (real time)", pairs, "bare Trigger")
    table("the same calls against a bare server that answers the same messages at once "
          "(a move: OK, nothing planned), its threads at this client's niceness (0): what a "
          "niceness-0 client on the job's cores sees, the job's precedence over it among it",
          same, "bare replay", "the same service types")
    table(f"the moves against that bare server served as the job is, its threads at the job's "
          f"niceness ({NICENESS}) too: the node's own cost, the plan's among it (goals: PTP "
          "accept <= 1.3, CP 20 mm accept <= 2, p50 and p99); the difference to the ratios above "
          "is what the job's precedence costs a niceness-0 client where they share the cores",
          ranked, "bare replay at the job's niceness", "the same service types")
    print(f"CPU per accept in the node (over its CPU meanwhile without calls, the arm moving: "
          f"taking the request, the checks and the plan, the answer), {CPU_CALLS} accepts each:")
    for name, seconds in cpu.items():
        print(f"  {name:<42} {seconds * 1e6:7.0f} us")
    print("the service callback alone in the node (the checks, the plan, the reply; every call "
          "of the run), p50 of its thread's CPU and of its wall time:")
    ptp_calls = handler_times["move_ptp_joint_rel"]      # the idle arm's accepts came last
    handler_times["move_ptp_joint_rel"] = ptp_calls[:-IDLE_CALLS]
    handler_times["move_ptp_joint_rel, arm idle"] = ptp_calls[-IDLE_CALLS:]
    for service, calls in sorted(handler_times.items(), reverse=True):
        cpu_s, wall_s = np.median(np.array(calls), axis=0)
        print(f"  {service:<42} {cpu_s * 1e6:7.0f} us CPU  {wall_s * 1e6:7.0f} us wall"
              f"   ({len(calls)} calls)")
    ros.close()


@contextmanager
def replay_server(ros: RosClient, replayed: dict[str, tuple[type, dict]],
                  *options: str) -> Iterator[None]:
    """`bench.trigger_server replay` of these arm operations (each with a call that moves
    nothing), each answering once before it is measured (`answered`)."""
    with running("bench.trigger_server", args=("replay", *options, *(ARM + op for op in replayed))):
        for op, (srv_type, fields) in replayed.items():
            answered(ros, srv_type, REPLAY + ARM + op, **fields)
        yield


def idle_accepts(ros: RosClient) -> dict:
    """A PTP accept on an idle arm (stopped, at rest: a move of 0°, which leaves it at rest)
    against the same-type bare node (`REPLAY`, running): the accept that wakes the control
    loop from its idle sleep, where a moving arm's finds it awake."""
    name = "move_ptp_joint_rel accept, arm idle (0°)"
    ros.call(srv.Stop, ARM + "stop")
    assert ros.spin_until(lambda: not ros.call(srv.GetState, ARM + "get_state").state & 0x02,
                          30.0), "the arm did not come to rest"

    def ptp(prefix: str = "") -> None:
        r = ros.call(srv.MovePTPJointRel, prefix + ARM + "move_ptp_joint_rel",
                     joint_points=[0.0] * 7)
        assert r.return_id.id == 0, r.return_id.comment
    return paired({name: lambda: ptp(REPLAY)}, [(name, ptp)], N, warmup=WARMUP, rounds=BLOCKS)


def planning_cpu(pid: int, call) -> float:
    """CPU seconds per call that the node spends over what it spends meanwhile without calls
    (the moving arm's simulation): CPU_CALLS calls in a row, then as long without."""
    c0, t0 = cpu_seconds(pid), time.monotonic()
    for _ in range(CPU_CALLS):
        call()
    c1, t1 = cpu_seconds(pid), time.monotonic()
    time.sleep(t1 - t0)            # the same wall time without calls: the node's own load
    idle = cpu_seconds(pid) - c1
    return (c1 - c0 - idle * (t1 - t0) / (time.monotonic() - t1)) / CPU_CALLS


def check_cpu() -> None:
    """CPU per accept of the checks and the plan without ROS (a warm core on this thread):
    PTP, a 20 mm CP line, and a 1,000 mm CP line at 5 % and 100 % (goal: <= 5 ms)."""
    from acti_motion.arm.poses import pose_to_hg
    world, ex, arm = simulated_arm(ARM_START, 5)
    arm.device.capacity = 100_000
    forward = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])

    def across(y: float) -> tuple:            # a pose on a 1,000 mm line across the front
        pose = np.eye(4)
        pose[:3, :3], pose[:3, 3] = forward, (0.45, y, 0.9)
        return pose_to_hg(pose), 90.0, 0

    def cpu(move, n: int) -> float:
        for i in range(3):
            assert move(i).ok
        t0 = time.process_time()
        for i in range(n):
            r = move(i)
            assert r.ok, r.comment
        return (time.process_time() - t0) / n

    print("\nCPU per accept without ROS (checks and plan, warm, this thread):")
    ptp = cpu(lambda i: arm.move_ptp_joint_rel([0.5 * (-1) ** i] * 7), 300)
    cp = cpu(lambda i: arm.move_linear_cartesian_rel(
        ([1.0, 0, 0, 20.0 * (-1) ** i, 0, 1.0, 0, 0, 0, 0, 1.0, 0], 0.0, 0)), 200)
    print(f"  {'move_ptp_joint_rel (0.5° each joint)':<42} {ptp * 1e6:7.0f} us")
    print(f"  {'move_linear_cartesian_rel (20 mm)':<42} {cp * 1e6:7.0f} us")
    arm.stop()
    while arm.device.busy:
        ex.step()
    assert arm.move_ptp_cartesian_abs(across(-0.5)).ok
    while arm.device.busy:
        ex.step()
    for ratio in (5, 100):
        arm.set_speed_cartesian(ratio)
        long = cpu(lambda i: arm.move_linear_cartesian_abs(across(0.5 if i % 2 == 0 else -0.5)),
                   20)
        print(f"  {f'move_linear_cartesian_abs (1,000 mm, {ratio} %)':<42} {long * 1e3:7.2f} ms"
              f"   (goal <= 5 ms)")
    world.close()


def motion_figures() -> None:
    from acti_motion.arm.poses import orientation_error_deg, pose_to_hg, position_error_mm
    from acti_motion.arm.trajectories import (TOPPRA_GRID, CartesianLimits, ConstAccelTiming,
                                              LinePath, time_optimal)

    world, ex, arm = simulated_arm(ARM_START, 60)

    def run(check=None) -> float:
        t0 = world.time
        while arm.device.busy:
            ex.step()
            if check:
                check()
        return world.time - t0

    print("\nPTP: duration in the simulation vs the analytic synchronized trapezoid")
    speed = arm.max_speed_joint * 0.6
    for delta in ([30.0] * 7, [5.0, -60.0, 0.0, 40.0, 0.0, 10.0, 0.0], [1.0] * 7):
        assert arm.move_ptp_joint_rel(delta).ok
        took = run()
        analytic = max(np.max(np.abs(delta) / speed), arm.accel_time_joint) + arm.accel_time_joint
        print(f"  Δq {str(delta):<42} sim {took:6.3f} s   analytic {analytic:6.3f} s"
              f"   ratio {took / analytic:5.3f}")

    print("\nCP at 100 %: duration vs the TOPP-RA time-optimal bound (same joint and Cartesian "
          "limits), tracking in the simulation")
    arm.set_speed_cartesian(100)
    cases = [("200 mm line", [0.2, 0.0, -0.2], None),
             ("300 mm line + 30° turn", [0.1, 0.25, -0.15], [0.0, 0.0, 30.0]),
             ("near the wrist singularity", None, None)]
    for name, dp, rot in cases:
        if dp is None:
            arm.move_ptp_joint_abs([20, 40, 10, -70, 30, 25, 0])
            run()
            target = arm.tool_pose(np.radians([-20, 40, -10, -70, -30, -25, 8]))
        else:
            target = arm.tool_pose(arm.device.hold.joints)
            target[:3, 3] += dp
            if rot is not None:
                import pinocchio as pin
                target[:3, :3] = pin.exp3(np.radians(rot)) @ target[:3, :3]
        P0 = arm.tool_pose(arm.device.hold.joints)
        elbow = math.degrees(arm.kin.arm_angle(arm.device.hold.joints))
        t0 = time.perf_counter()
        r = arm.move_linear_cartesian_abs((pose_to_hg(target), elbow, 0))
        plan_ms = (time.perf_counter() - t0) * 1e3
        assert r.ok, r.comment
        motion = arm.device.queue[0].motion
        path = motion.path
        v, w = arm.max_speed_cartesian
        limits = CartesianLimits(v / 1000, math.radians(w), arm.accel_time_cartesian,
                                 np.radians(arm.max_speed_joint),
                                 np.radians(arm.max_speed_joint) / arm.min_accel_time_joint)
        line = LinePath(P0, target)
        extents = np.array([line.length, line.angle, 0.0])
        bound = time_optimal(path.ss, path.qs, extents, limits, TOPPRA_GRID).duration
        deviation = []

        def check():
            P = arm.tool_pose(world.arm_positions())
            v_ = P[:3, 3] - P0[:3, 3]
            d = target[:3, 3] - P0[:3, 3]
            deviation.append(np.linalg.norm(v_ - np.dot(v_, d) / np.dot(d, d) * d) * 1000)
        took = run(check)
        for _ in range(60):
            ex.step()
        P = arm.tool_pose(world.arm_positions())
        timing = "TOPP-RA" if isinstance(motion.timing, ConstAccelTiming) else "trapezoid"
        print(f"  {name:<28} {timing:<9} plan {plan_ms:6.1f} ms  duration {took:6.3f} s  "
              f"bound {bound:6.3f} s  ratio {took / bound:5.3f}  max dev {max(deviation):.4f} mm"
              f"  final {position_error_mm(P, target):.4f} mm"
              f" {orientation_error_deg(P, target):.4f}°")
    world.close()


if __name__ == "__main__":
    check_cpu()
    motion_figures()
    accept_latency()
