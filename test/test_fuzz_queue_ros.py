"""A queued move survives every request the spec does not make a stop, on both nodes over DDS.

Each case queues a slow move (the base: 250 mm in about 1.5 s; the arm: a slow PTP) and a short
one behind it, in real time, waits until the first runs (the second waits, queued and not
started), sends a few random requests to one service (its fields filled from the request type:
good values beside NaN, inf, 1e308, 5e-324, zero and negative ones), puts the speed settings
back (a request may have made a move crawl: that is allowed, a discard is not) and waits for
both moves: `wait_motion` must say completed for each. One table for both nodes: per node, how
to make it ready, how to queue its two moves, the services left out because the spec makes them
a stop, a hold or a take-over (with the reason), the fields held where only their other values
stop (set_power and set_servo on: off is a stop), and the services sent only values the node
must refuse (the arm's soft limits: a valid narrower one stops the arm by design, a refused one
must change nothing), each answer checked to be a refusal. Every other service of the node's
operation table is fuzzed. Seeds are fixed per service, so a failure repeats."""
from __future__ import annotations

import functools
import math
import random
import zlib
from dataclasses import dataclass
from typing import Any, Callable

import pytest
from acti_msgs import srv
from acti_msgs.action import VehicleWaitMotion, WaitMotion
from acti_msgs.msg import LimitValue, VehiclePosition, VehicleVelocity
from rosidl_parser.definition import AbstractNestedType, Array, BasicType, NamespacedType

from acti_bringup.serving.conversions import _message_class, fill
from acti_middle_node.operations import OPERATIONS as ARM_OPERATIONS
from ros_harness import Actions, node_fixture, wait_until
from vehicle_node.operations import OPERATIONS as BASE_OPERATIONS

job = node_fixture("acti_bringup", "real_time_factor:=1.0")   # the pace: the requests land while the move runs

ARM, BASE = "/acti_middle_node/", "/vehicle_node/"
REQUESTS = 5                     # random requests per case
FLOATS_BAD = [math.nan, math.inf, -math.inf, 1e308, -1e308, 5e-324, 0.0, -1.0, -100.0]
FLOATS_GOOD = [1.0, 5.0, 20.0, 50.0, 100.0, 300.0]
INT_RANGES = {"int8": (-2**7, 2**7 - 1), "uint8": (0, 2**8 - 1), "int16": (-2**15, 2**15 - 1),
              "uint16": (0, 2**16 - 1), "int32": (-2**31, 2**31 - 1), "uint32": (0, 2**32 - 1),
              "int64": (-2**63, 2**63 - 1), "uint64": (0, 2**64 - 1)}


def random_value(slot: Any, rng: random.Random) -> Any:
    """A core value (as `fill` takes it) for a field of type `slot`."""
    if isinstance(slot, NamespacedType):
        cls = _message_class(slot)
        return tuple(random_value(s, rng) for s in cls.SLOT_TYPES)
    if isinstance(slot, AbstractNestedType):
        n = slot.size if isinstance(slot, Array) else rng.choice([0, 1, 6, 7, 8])
        return [random_value(slot.value_type, rng) for _ in range(n)]
    if isinstance(slot, BasicType):
        t = slot.typename
        if t == "boolean":
            return rng.random() < 0.5
        if t in ("double", "float"):
            return rng.choice(FLOATS_BAD if rng.random() < 0.5 else FLOATS_GOOD)
        lo, hi = INT_RANGES.get(t, (0, 255))
        return max(lo, min(hi, rng.choice([0, -1, 1, 2, 7, 50, 100, 101, 1000, lo, hi])))
    return rng.choice(["", "x"])                  # strings


def random_fields(srv_type: type, rng: random.Random) -> dict[str, Any]:
    """A request's fields, each random (nested messages built as the node's replies are)."""
    request = srv_type.Request()
    fill(request, {name: random_value(slot, rng) for name, slot in
                   zip(request.get_fields_and_field_types(), srv_type.Request.SLOT_TYPES)})
    return {name: getattr(request, name) for name in request.get_fields_and_field_types()}


@dataclass(frozen=True)
class Node:
    """One node of the table: its services, how to ready it and queue its two moves (their
    ids: the slow one, the short one behind it), how to put its speed back, its wait action,
    what is left out, and the services fuzzed with refused values only (a generator of a
    request's fields from the client and the case's random source; `refused` tells a refusal)."""
    path: str
    operations: tuple
    ready: Callable[[Any], None]
    queue_moves: Callable[[Any], tuple[int, int]]
    speed_back: Callable[[Any], None]
    wait_action: type
    left_out: dict[str, str]
    fixed: dict[str, dict[str, Any]]          # fields held, where only their other values stop
    bad_only: dict[str, Callable[[Any, random.Random], dict[str, Any]]]
    refused: Callable[[Any], bool]


def call(ros, path: str, srv_type: type, **fields) -> Any:
    return ros.call(srv_type, path, **fields)


# --- the base ---------------------------------------------------------------------------------
def base_ready(ros) -> None:
    call(ros, BASE + "stop", srv.VehicleStop)
    call(ros, BASE + "unlock", srv.VehicleUnlock)
    call(ros, BASE + "set_joystick", srv.VehicleSetJoystick, on_off=False)
    assert call(ros, BASE + "set_power", srv.VehicleSetPower, on_off=True).success
    assert call(ros, BASE + "set_servo", srv.VehicleSetServo, on_off=True).success
    assert wait_until(lambda: call(ros, BASE + "get_state", srv.VehicleGetState).state == 0x010
                      or not call(ros, BASE + "clear_alarm", srv.VehicleClearAlarm), 30.0)
    base_speed_back(ros)
    assert call(ros, BASE + "set_acceleration", srv.VehicleSetAcceleration,
                accel=VehicleVelocity(translation=500.0, rotation=90.0)).success


def base_speed_back(ros) -> None:
    assert call(ros, BASE + "set_velocity", srv.VehicleSetVelocity, vel=VehicleVelocity(translation=200.0, rotation=45.0)).success


def base_queue_moves(ros) -> tuple[int, int]:
    """250 mm at 200 mm/s and 500 mm/s² (about 1.5 s with the settle), then 30 mm further
    (move_linear_abs: a "servo on" move, which queues behind a moving base)."""
    here = call(ros, BASE + "get_position", srv.VehicleGetPosition).pos
    r = call(ros, BASE + "move_forward", srv.VehicleMoveForward, x=250.0)
    assert r.success and not r.message, r.message
    heading = math.radians(here.theta)
    beyond = VehiclePosition(x=here.x + 280.0 * math.cos(heading),
                             y=here.y + 280.0 * math.sin(heading), theta=here.theta)
    second = call(ros, BASE + "move_linear_abs", srv.VehicleMoveLinearAbs, pos=beyond)
    assert second.success and not second.message, second.message
    return r.motion_id, second.motion_id


# --- the arm ----------------------------------------------------------------------------------
def arm_ready(ros) -> None:
    call(ros, ARM + "stop", srv.Stop)
    call(ros, ARM + "clear_alarms", srv.ClearAlarms)
    assert call(ros, ARM + "servo_on", srv.ServoON).return_id.id == 0
    assert wait_until(lambda: not call(ros, ARM + "get_state", srv.GetState).state & 0x02, 30.0)
    arm_speed_back(ros)


@functools.cache
def arm_startup_speeds(ros) -> tuple[float, ...]:
    """The joints' max speeds as the node started: read by the first case's ready, before any
    case fuzzes them."""
    return tuple(call(ros, ARM + "get_max_speed_joint", srv.GetMaxSpeedJoint).speed)


def arm_speed_back(ros) -> None:
    """What times a PTP back as the node started (the accel times: config/acti_ros2.yaml), at
    10 % speed: a case's settings left slow made the next cases' moves crawl (10 s a case)."""
    for name, srv_type, fields in (
            ("set_max_speed_joint", srv.SetMaxSpeedJoint, {"speed": arm_startup_speeds(ros)}),
            ("set_min_accel_time_joint", srv.SetMinAccelTimeJoint, {"acl_time": 0.1}),
            ("set_accel_time_joint", srv.SetAccelTimeJoint, {"acl_time": 0.3}),
            ("set_speed_joint", srv.SetSpeedJoint, {"spd_ratio": 10}),
            ("set_speed_cartesian", srv.SetSpeedCartesian, {"spd_ratio": 10})):
        answer = call(ros, ARM + name, srv_type, **fields).return_id
        assert answer.id == 0, f"{name}: {answer.comment}"


def arm_queue_moves(ros) -> tuple[int, int]:
    """J1 by 10 degree (alternately back), then 2 degree back, at 10 % of the joint speed."""
    here = call(ros, ARM + "get_feedback_pos_joint", srv.GetFeedbackPosJoint).pos
    step = -10.0 if here[0] > 0.0 else 10.0
    ids = []
    for j1 in (step, -step / 5):
        r = call(ros, ARM + "move_ptp_joint_rel", srv.MovePTPJointRel,
                 joint_points=[j1] + [0.0] * (len(here) - 2))
        assert r.return_id.id == 0, r.return_id.comment
        ids.append(r.motion_id)
    return ids[0], ids[1]


# (upper, lower) the arm refuses as a joint and as a Cartesian soft limit (settings.py
# _limit_value, core.py set_soft_limit_*): not finite, upper below lower, beyond any joint's
# hardware range and the ±100 m Cartesian bound
BAD_LIMITS = [(math.nan, -10.0), (10.0, math.nan), (math.inf, -10.0), (10.0, -math.inf),
              (-10.0, 10.0), (0.0, 5e-324), (1e308, -1e308), (2e5, 0.0)]
WIDE_LIMIT = (150.0, -150.0)              # within the joints' range and the Cartesian bound


def limit_rows(rng: random.Random, count: int) -> list[LimitValue]:
    """`count` limits, each wide or bad, at least one bad: the request is refused whole."""
    rows = [rng.choice(BAD_LIMITS + [WIDE_LIMIT]) for _ in range(count)]
    rows[rng.randrange(count)] = rng.choice(BAD_LIMITS)
    return [LimitValue(upper=u, lower=lo) for u, lo in rows]


def bad_joint_limits(ros, rng: random.Random) -> dict[str, Any]:
    """Limits for every joint with one bad, or wide ones for too few or too many joints."""
    joints = len(call(ros, ARM + "get_soft_limit_joint", srv.GetSoftLimitJoint).soft_limit)
    if rng.random() < 0.5:
        return {"soft_limit": limit_rows(rng, joints)}
    wrong = rng.choice([0, 1, joints - 1, joints + 1])
    return {"soft_limit": [LimitValue(upper=WIDE_LIMIT[0], lower=WIDE_LIMIT[1])] * wrong}


def bad_cartesian_limits(ros, rng: random.Random) -> dict[str, Any]:
    return dict(zip(("x_limit", "y_limit", "z_limit"), limit_rows(rng, 3)))


NODES = {
    "base": Node(BASE, BASE_OPERATIONS, base_ready, base_queue_moves, base_speed_back,
                 VehicleWaitMotion, {
                     "stop": "a stop (1.4.33)", "pause": "a hold until resume (1.4.22)",
                     "move_jog": "takes over the running move (by design)",
                     "move_continuous_rel": "takes over the running move (1.4.15)"},
                 {"set_power": {"on_off": True}, "set_servo": {"on_off": True}},  # off stops
                 {}, lambda answer: not answer.success),
    "arm": Node(ARM, ARM_OPERATIONS, arm_ready, arm_queue_moves, arm_speed_back, WaitMotion, {
        "stop": "a stop", "pause": "a hold until resume", "servo_off": "a stop"}, {},
        # a limit the arm is past stops it (alarm 0x4, 0x5); set_soft_limit_joint answers
        # STATUS_ERR while the arm moves, before it looks at the values (the cartesian one checks)
        {"set_soft_limit_joint": bad_joint_limits,
         "set_soft_limit_cartesian": bad_cartesian_limits},
        lambda answer: answer.return_id.id != 0),
}
CASES = [(node, op.name) for node, n in NODES.items() for op in n.operations
         if op.name not in n.left_out]


@pytest.mark.parametrize("node, service", CASES, ids=[f"{n}.{s}" for n, s in CASES])
def test_a_request_that_is_no_stop_keeps_the_queued_move(ros, job, node, service):
    n = NODES[node]
    srv_type = next(op.srv_type for op in n.operations if op.name == service)
    rng = random.Random(zlib.crc32(f"{node}.{service}".encode()))
    n.ready(ros)
    waits = Actions(ros, n.wait_action, n.path + "wait_motion")
    first, second = n.queue_moves(ros)
    running: list[int] = []
    results = [waits.send(feedback, motion_id=motion_id, timeout=120.0).get_result_async()
               for motion_id, feedback in ((first, lambda f: running.append(
                   f.feedback.current_motion_id)), (second, None))]
    assert ros.spin_until(lambda: first in running or results[0].done(), 30.0)
    assert not results[0].done(), f"{node} motion {first} was over before the requests"
    assert not results[1].done(), f"{node} motion {second} was over before the requests"
    sent = []
    for _ in range(REQUESTS):                 # while the first runs and the second waits
        if service in n.bad_only:
            fields = n.bad_only[service](ros, rng)
            answer = ros.call(srv_type, n.path + service, **fields)
            assert n.refused(answer), f"{node}.{service} took {fields}: {answer}"
        else:
            fields = random_fields(srv_type, rng) | n.fixed.get(service, {})
            ros.call(srv_type, n.path + service, **fields)
        sent.append(fields)
    n.speed_back(ros)
    for motion_id, result in zip((first, second), results):
        assert ros.wait(result, 120.0)
        outcome = result.result().result
        assert outcome.completed, (f"{node} motion {motion_id} (of {first}, {second}) discarded "
                                   f"after {service} {sent}: {getattr(outcome, 'message', '')}")
    assert job.alive()
