"""A queued move survives every request the spec does not make a stop, on both nodes over DDS.

Each case queues a slow move (the base: 250 mm in about 1.5 s; the arm: a slow PTP), in real
time, waits until it runs, sends a few random requests to one service (its fields filled from
the request type: good values beside NaN, inf, 1e308, 5e-324, zero and negative ones) while it
runs, puts the speed settings back (a request may have made the move crawl: that is allowed, a
discard is not) and waits for the move: `wait_motion` must say completed. One table for both nodes: per node, how to make it
ready, how to queue its slow move, the services left out because the spec makes them a stop, a
hold or a take-over (with the reason), and the fields held where only their other values stop
(set_power and set_servo on: off is a stop). Every other service of the node's operation
table is fuzzed. Seeds are fixed per service, so a failure repeats."""
from __future__ import annotations

import math
import random
import zlib
from dataclasses import dataclass
from typing import Any, Callable

import pytest
from acti_msgs import srv
from acti_msgs.action import VehicleWaitMotion, WaitMotion
from acti_msgs.msg import VehicleVelocity
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
    """One node of the table: its services, how to ready it and queue its slow move (the
    move's id), how to put its speed back, its wait action and what is left out."""
    path: str
    operations: tuple
    ready: Callable[[Any], None]
    slow_move: Callable[[Any], int]
    speed_back: Callable[[Any], None]
    wait_action: type
    left_out: dict[str, str]
    fixed: dict[str, dict[str, Any]]          # fields held, where only their other values stop


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


def base_slow_move(ros) -> int:
    """250 mm at 200 mm/s and 500 mm/s²: about 1.5 s with the settle."""
    r = call(ros, BASE + "move_forward", srv.VehicleMoveForward, x=250.0)
    assert r.success and not r.message, r.message
    return r.motion_id


# --- the arm ----------------------------------------------------------------------------------
def arm_ready(ros) -> None:
    call(ros, ARM + "stop", srv.Stop)
    call(ros, ARM + "clear_alarms", srv.ClearAlarms)
    assert call(ros, ARM + "servo_on", srv.ServoON).return_id.id == 0
    assert wait_until(lambda: not call(ros, ARM + "get_state", srv.GetState).state & 0x02, 30.0)
    arm_speed_back(ros)


def arm_speed_back(ros) -> None:
    assert call(ros, ARM + "set_speed_joint", srv.SetSpeedJoint, spd_ratio=10).return_id.id == 0
    assert call(ros, ARM + "set_speed_cartesian", srv.SetSpeedCartesian,
                spd_ratio=10).return_id.id == 0


def arm_slow_move(ros) -> int:
    """J1 by 10 degree (alternately back) at 10 % of the joint speed."""
    here = call(ros, ARM + "get_feedback_pos_joint", srv.GetFeedbackPosJoint).pos
    step = -10.0 if here[0] > 0.0 else 10.0
    r = call(ros, ARM + "move_ptp_joint_rel", srv.MovePTPJointRel,
             joint_points=[step] + [0.0] * (len(here) - 2))
    assert r.return_id.id == 0, r.return_id.comment
    return r.motion_id


NODES = {
    "base": Node(BASE, BASE_OPERATIONS, base_ready, base_slow_move, base_speed_back,
                 VehicleWaitMotion, {
                     "stop": "a stop (1.4.33)", "pause": "a hold until resume (1.4.22)",
                     "move_jog": "takes over the running move (by design)",
                     "move_continuous_rel": "takes over the running move (1.4.15)"},
                 {"set_power": {"on_off": True}, "set_servo": {"on_off": True}}),  # off stops
    "arm": Node(ARM, ARM_OPERATIONS, arm_ready, arm_slow_move, arm_speed_back, WaitMotion, {
        "stop": "a stop", "pause": "a hold until resume", "servo_off": "a stop",
        "set_soft_limit_joint": "a limit the arm is past stops it (alarm 0x4)",
        "set_soft_limit_cartesian": "a limit the arm is past stops it (alarm 0x5)"}, {}),
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
    motion_id = n.slow_move(ros)
    running: list[int] = []
    wait = waits.send(lambda f: running.append(f.feedback.current_motion_id),
                      motion_id=motion_id, timeout=120.0)
    result = wait.get_result_async()
    assert ros.spin_until(lambda: motion_id in running or result.done(), 30.0)
    assert not result.done(), f"{node} motion {motion_id} was over before the requests"
    sent = []
    for _ in range(REQUESTS):                 # while the move runs
        fields = random_fields(srv_type, rng) | n.fixed.get(service, {})
        sent.append(fields)
        ros.call(srv_type, n.path + service, **fields)
    n.speed_back(ros)
    assert ros.wait(result, 120.0)
    result = result.result().result
    assert result.completed, (f"{node} motion {motion_id} discarded after {service} "
                              f"{sent}: {getattr(result, 'message', '')}")
    assert job.alive()
