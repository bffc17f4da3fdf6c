"""Every service of both nodes (the 78 rows of the two operation tables) over DDS on the main
job: one good request, answered OK / true, and one bad request (wrong length, NaN, out of range
or the wrong state), answered with the spec's error (arm: the RETURN_ID, vehicle: false) and a
comment that says what was wrong. No traceback in the log (the fixture checks), the node stays
up. A few operations take no input and are valid in every state: they have no bad request, and
the table says so (`NO_BAD`)."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable

import pytest
from acti_msgs.msg import CarPosWithElbow, CartesianSpeed, LimitValue
from acti_msgs.msg import VehiclePoint, VehiclePosition, VehicleVelocity

from acti_middle_node.operations import OPERATIONS as ARM_OPERATIONS
from ros_harness import node_fixture, wait_until
from vehicle_node.operations import OPERATIONS as BASE_OPERATIONS

job = node_fixture("acti_bringup")

ARM, BASE = "/acti_middle_node/", "/vehicle_node/"
OK, STATUS_ERR, VALUE_ERR, NOT_SV_ON_ERR = 0, -2, -3, -4
NAN = math.nan
IDENTITY = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0]
SRV = {op.name: op.srv_type for op in ARM_OPERATIONS} | {
    "base." + op.name: op.srv_type for op in BASE_OPERATIONS}

Request = Callable[[Any], dict] | dict


def moved(dx: float = 0.0, dy: float = 0.0, dz: float = 0.0, base: list | None = None) -> list:
    m = list(base or IDENTITY)
    m[3] += dx
    m[7] += dy
    m[11] += dz
    return m


def rel(dx=0.0, dy=0.0, dz=0.0) -> CarPosWithElbow:
    return CarPosWithElbow(car_pos=moved(dx, dy, dz), elbow=0.0, struct_flag=0)


def here_plus(ros, dx: float, dy: float = 0.0) -> CarPosWithElbow:
    """An absolute pose (dx, dy) mm from where the arm is, in its elbow angle and configuration."""
    pos = call(ros, "get_feedback_pos_cartesian").pos
    return CarPosWithElbow(car_pos=moved(dx, dy, base=list(pos.car_pos)), elbow=pos.elbow,
                           struct_flag=pos.struct_flag)


def cartesian_limits(ros) -> dict:
    r = call(ros, "get_soft_limit_cartesian")
    return {"x_limit": r.x_limit, "y_limit": r.y_limit, "z_limit": r.z_limit}


@dataclass(frozen=True)
class Row:
    """One operation: its good request, its bad one (None: NO_BAD), the code the bad one gets
    (arm; the vehicle answers false), words its comment must hold, and calls that put the
    device in the wrong state before the bad request."""
    name: str
    good: Request = field(default_factory=dict)
    bad: Request | None = None
    code: int = VALUE_ERR
    says: str = ""
    wrong_state: tuple[tuple[str, dict], ...] = ()


NO_BAD = None
SERVO_OFF = (("servo_off", {}),)
UNPOWERED = (("base.set_servo", {"on_off": False}), ("base.set_power", {"on_off": False}))

ARM_ROWS = [
    Row("clear_alarms", bad=NO_BAD),
    Row("get_active_alarm", bad=NO_BAD),
    Row("get_feedback_pos_joint", bad=NO_BAD),
    Row("get_manip_info", bad=NO_BAD),
    Row("get_soft_limit_joint", bad=NO_BAD),
    Row("get_state", bad=NO_BAD),
    Row("servo_off", bad=NO_BAD),
    Row("servo_on", bad=NO_BAD),
    Row("set_soft_limit_joint",
        good=lambda ros: {"soft_limit": call(ros, "get_soft_limit_joint").soft_limit},
        bad={"soft_limit": [LimitValue(upper=10.0, lower=-10.0)] * 2}, says="soft_limit"),
    Row("close_gripper", bad={}, code=NOT_SV_ON_ERR, says="servo", wrong_state=SERVO_OFF),
    Row("get_base_offset", bad=NO_BAD),
    Row("get_feedback_pos_cartesian", bad=NO_BAD),
    Row("get_max_speed_cartesian", bad=NO_BAD),
    Row("get_max_speed_joint", bad=NO_BAD),
    Row("get_min_accel_time_cartesian", bad=NO_BAD),
    Row("get_min_accel_time_joint", bad=NO_BAD),
    Row("get_soft_limit_cartesian", bad=NO_BAD),
    Row("move_gripper", good={"angle_ratio": 50}, bad={"angle_ratio": 101}, says="101"),
    Row("move_linear_cartesian_abs", good=lambda ros: {"car_point": here_plus(ros, 5.0)},
        bad={"car_point": CarPosWithElbow(car_pos=moved(NAN))}),
    Row("move_linear_cartesian_rel", good={"car_point": rel(5.0)},
        bad={"car_point": rel(math.inf)}),
    Row("move_ptp_cartesian_abs", good=lambda ros: {"car_point": here_plus(ros, -5.0)},
        bad={"car_point": CarPosWithElbow(car_pos=moved(1e308))}),
    Row("move_ptp_cartesian_rel", good={"car_point": rel(dz=5.0)},
        bad={"car_point": rel(dz=NAN)}),
    Row("move_ptp_joint_abs",
        good=lambda ros: {"joint_points": call(ros, "get_feedback_pos_joint").pos[:7]},
        bad={"joint_points": [0.0] * 6}, says="7"),
    Row("move_ptp_joint_rel", good={"joint_points": [1.0] * 7},
        bad={"joint_points": [NAN] * 7}),
    Row("open_gripper", bad={}, code=NOT_SV_ON_ERR, says="servo", wrong_state=SERVO_OFF),
    Row("pause", bad=NO_BAD),
    Row("resume", bad=NO_BAD),
    Row("stop", bad=NO_BAD),
    Row("set_accel_time_cartesian", good={"acl_time": 0.3}, bad={"acl_time": -1.0}),
    Row("set_accel_time_joint", good={"acl_time": 0.3}, bad={"acl_time": 0.0}),
    Row("set_base_offset", good={"offset": IDENTITY}, bad={"offset": moved(NAN)}),
    # the spec lists only STATUS_ERR for setControlPointOffset: any other refusal is NG
    Row("set_control_point_offset", good={"offset": IDENTITY}, bad={"offset": moved(dz=NAN)},
        code=-1, says="finite"),
    Row("set_max_speed_cartesian",
        good=lambda ros: {"speed": call(ros, "get_max_speed_cartesian").speed},
        bad={"speed": CartesianSpeed(translation=0.0, rotation=90.0)}, says="speed"),
    Row("set_max_speed_joint",
        good=lambda ros: {"speed": call(ros, "get_max_speed_joint").speed},
        bad={"speed": [90.0] * 3}),
    Row("set_min_accel_time_cartesian",
        good=lambda ros: {"acl_time": call(ros, "get_min_accel_time_cartesian").acl_time},
        bad={"acl_time": -0.5}),
    Row("set_min_accel_time_joint",
        good=lambda ros: {"acl_time": call(ros, "get_min_accel_time_joint").acl_time},
        bad={"acl_time": -0.5}),
    Row("set_soft_limit_cartesian", good=lambda ros: cartesian_limits(ros),
        bad={"x_limit": LimitValue(upper=-100.0, lower=100.0),
             "y_limit": LimitValue(upper=1000.0, lower=-1000.0),
             "z_limit": LimitValue(upper=1000.0, lower=-1000.0)}),
    Row("set_speed_cartesian", good={"spd_ratio": 50}, bad={"spd_ratio": 101}),
    Row("set_speed_joint", good={"spd_ratio": 50}, bad={"spd_ratio": 101}),
    Row("move_circular_cartesian_abs",
        good=lambda ros: {"car_point_r": here_plus(ros, 5.0, 5.0), "car_point_t": here_plus(ros, 10.0)},
        bad={"car_point_r": CarPosWithElbow(car_pos=moved(NAN)),
             "car_point_t": CarPosWithElbow(car_pos=moved(NAN))}),
    Row("move_circular_cartesian_rel", good={"car_point_r": rel(5.0, 5.0),
                                             "car_point_t": rel(10.0)},
        bad={"car_point_r": rel(5.0, NAN), "car_point_t": rel(10.0)}),
    Row("set_home",
        good=lambda ros: {"joint_point": call(ros, "get_home").joint_point},
        bad={"joint_point": [0.0] * 8}),
    Row("get_home", bad=NO_BAD),
    Row("go_home", bad={}, code=NOT_SV_ON_ERR, says="servo", wrong_state=SERVO_OFF),
]

BASE_ROWS = [
    Row("base.clear_alarm", bad=NO_BAD),
    Row("base.get_acceleration_limit", bad=NO_BAD),
    Row("base.get_active_alarm", good={"num_of_alarm": 8}, bad=NO_BAD),  # a count: < 0 is none
    Row("base.get_battery_voltage", bad=NO_BAD),
    Row("base.get_default_acceleration", bad=NO_BAD),
    Row("base.get_default_velocity", bad=NO_BAD),
    Row("base.get_if_version", bad=NO_BAD),
    Row("base.get_input", good={"ioid": 1}, bad={"ioid": 9999}, says="not declared"),
    Row("base.get_position", bad=NO_BAD),
    Row("base.get_servo_status", good={"axisid": 0}, bad={"axisid": 9999}),
    Row("base.get_state", bad=NO_BAD),
    Row("base.get_velocity_limit", bad=NO_BAD),
    Row("base.get_version", bad=NO_BAD),
    Row("base.move_circular_rel",
        good={"center_point": VehiclePoint(x=0.0, y=500.0), "theta": 5.0},
        bad={"center_point": VehiclePoint(x=0.0, y=500.0), "theta": NAN}),
    Row("base.move_continuous_rel", good={"pos": VehiclePosition(x=20.0, y=0.0, theta=0.0)},
        bad={"pos": VehiclePosition(x=NAN, y=0.0, theta=0.0)}),
    Row("base.move_cruise_abs", good=lambda ros: {"cruise_point": base_ahead(ros, 30.0)},
        bad={"cruise_point": VehiclePoint(x=math.inf, y=0.0)}),
    Row("base.move_forward", good={"x": 20.0}, bad={"x": NAN}),
    Row("base.move_jog", good={"x_vel": 10.0, "y_vel": 0.0, "theta_vel": 0.0},
        bad={"x_vel": NAN, "y_vel": 0.0, "theta_vel": 0.0}),
    Row("base.move_linear_abs", good=lambda ros: {"pos": base_pose_ahead(ros, 20.0)},
        bad={"pos": VehiclePosition(x=NAN, y=0.0, theta=0.0)}),
    Row("base.move_linear_rel", good={"pos": VehiclePosition(x=20.0, y=0.0, theta=0.0)},
        bad={"pos": VehiclePosition(x=0.0, y=0.0, theta=NAN)}),
    Row("base.move_turn", good={"theta": 5.0}, bad={"theta": math.inf}),
    Row("base.pause", bad=NO_BAD),
    Row("base.resume", bad=NO_BAD),
    Row("base.set_acceleration",
        good=lambda ros: {"accel": same_fields(
            VehicleVelocity, call(ros, "base.get_default_acceleration").default_accel)},
        bad={"accel": VehicleVelocity(translation=-1.0, rotation=90.0)}),
    Row("base.set_digital_sensor_lock", good={"on_off": False}, bad=NO_BAD),
    Row("base.set_jog_timeout", good={"timeout": 500}, bad={"timeout": -1}),
    Row("base.set_joystick", good={"on_off": False}, bad=NO_BAD),
    Row("base.set_output", good={"ioid": 1, "output": 1, "mask": 1},
        bad={"ioid": 9999, "output": 1, "mask": 1}),
    Row("base.set_position", good=lambda ros: {"pos": call(ros, "base.get_position").pos},
        bad={"pos": VehiclePosition(x=0.0, y=0.0, theta=NAN)}),
    Row("base.set_power", good={"on_off": True}, bad=NO_BAD),
    Row("base.set_servo", good={"on_off": True}, bad={"on_off": True}, says="power",
        wrong_state=UNPOWERED),
    Row("base.set_velocity",
        good=lambda ros: {"vel": call(ros, "base.get_default_velocity").default_vel},
        bad={"vel": VehicleVelocity(translation=NAN, rotation=90.0)}),
    Row("base.stop", bad=NO_BAD),
    Row("base.unlock", bad=NO_BAD),
]
ROWS = ARM_ROWS + BASE_ROWS


def call(ros, name: str, **fields):
    path = BASE + name.removeprefix("base.") if name.startswith("base.") else ARM + name
    return ros.call(SRV[name], path, **fields)


def base_pose_ahead(ros, dx: float) -> VehiclePosition:
    pos = call(ros, "base.get_position").pos
    return VehiclePosition(x=pos.x + dx * math.cos(math.radians(pos.theta)),
                           y=pos.y + dx * math.sin(math.radians(pos.theta)), theta=pos.theta)


def base_ahead(ros, dx: float) -> VehiclePoint:
    pose = base_pose_ahead(ros, dx)
    return VehiclePoint(x=pose.x, y=pose.y)


def same_fields(cls: type, msg: Any) -> Any:
    """msg as a `cls` of the same field names (the IDL gives setAcceleration a velocity type)."""
    return cls(**{f: getattr(msg, f) for f in cls.get_fields_and_field_types()})


def outcome(name: str, reply) -> tuple[bool, int | None, str]:
    """(accepted, arm code or None, comment) of either node's reply."""
    if name.startswith("base."):
        return reply.success, None, reply.message
    return reply.return_id.id == OK, reply.return_id.id, reply.return_id.comment


def ready(ros) -> None:
    """Both devices at rest, servo on, no alarm, speeds set: the state every row starts from."""
    for name, fields in (("stop", {}), ("clear_alarms", {}), ("servo_on", {}),
                         ("set_speed_joint", {"spd_ratio": 50}),
                         ("set_speed_cartesian", {"spd_ratio": 50}),
                         ("base.stop", {}), ("base.clear_alarm", {}),
                         ("base.set_power", {"on_off": True}), ("base.set_servo", {"on_off": True})):
        call(ros, name, **fields)
    assert wait_until(lambda: not call(ros, "get_state").state & 0x02
                      and call(ros, "base.get_state").state == 0x010, 30.0), "devices not at rest"


def request(row_request: Request, ros) -> dict:
    return row_request(ros) if callable(row_request) else row_request


def test_the_table_covers_every_service_once():
    assert sorted(r.name for r in ROWS) == sorted(SRV) and len(SRV) == 78
    no_input = {name for name, t in SRV.items() if not t.Request.get_fields_and_field_types()}
    lacking = {r.name for r in ROWS if r.bad is NO_BAD}
    # only operations without input, with a boolean switch or a count can lack a bad request
    assert lacking - no_input <= {"base.set_digital_sensor_lock", "base.set_joystick",
                                  "base.set_power", "base.get_active_alarm"}


@pytest.mark.parametrize("row", ROWS, ids=[r.name for r in ROWS])
def test_good_and_bad_request(ros, job, row):
    ready(ros)
    accepted, code, comment = outcome(row.name, call(ros, row.name, **request(row.good, ros)))
    assert accepted, f"{row.name} refused a good request: {code} {comment}"
    if row.bad is not NO_BAD:
        ready(ros)
        for name, fields in row.wrong_state:
            call(ros, name, **fields)
        accepted, code, comment = outcome(row.name, call(ros, row.name, **request(row.bad, ros)))
        assert not accepted, f"{row.name} accepted a bad request"
        if code is not None:
            assert code == row.code, f"{row.name}: {code} {comment}"
        assert comment and row.says in comment, f"{row.name}: comment {comment!r}"
    assert job.alive()
