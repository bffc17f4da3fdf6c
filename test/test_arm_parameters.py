"""The nodes' parameters over DDS: every one described; an integer given at start-up for a double
is that double; on acti_middle_node the settable ones take
effect through the matching service's validation (seen by its getter) and refuse a bad value with
the service's reason, read-only ones refuse every set; a change through a service shows in the
parameter. vehicle_node's parameters are all read-only (none is settable yet)."""
from dataclasses import dataclass, field

import pytest
from acti_msgs import srv
from acti_msgs.msg import CartesianSpeed, LimitValue
from rcl_interfaces.msg import Parameter, ParameterType, ParameterValue
from rcl_interfaces.srv import (DescribeParameters, GetParameters, ListParameters, SetParameters,
                                SetParametersAtomically)

from acti_bringup.serving.parameters import field_descriptions
from ros_harness import node_fixture, wait_until

# rate_hz and clock_rate_hz as integers, as a user types them: they mean 250.0 and 100.0
arm_node = node_fixture("acti_middle_node", "queue_size:=4", "rate_hz:=250", "clock_rate_hz:=100")
vehicle_node = node_fixture("vehicle_node")
ARM = "/acti_middle_node/"
BASE = "/vehicle_node/"
READ_ONLY = " (read-only: set at start-up)"
ROS_OWN = ("use_sim_time", "start_type_description_service")
SETTABLE = {"accel_time_joint", "min_accel_time_joint", "accel_time_cartesian",
            "min_accel_time_cartesian", "max_speed_translation", "max_speed_rotation",
            "soft_limit_cartesian", "home_joints_deg"}


def value(kind, x):
    field = {ParameterType.PARAMETER_DOUBLE: "double_value",
             ParameterType.PARAMETER_INTEGER: "integer_value",
             ParameterType.PARAMETER_DOUBLE_ARRAY: "double_array_value"}[kind]
    return ParameterValue(type=kind, **{field: x})


def set_param(ros, name, kind, x):
    r = ros.call(SetParameters, ARM + "set_parameters",
                 parameters=[Parameter(name=name, value=value(kind, x))])
    return r.results[0]


def get_param(ros, name):
    return ros.call(GetParameters, ARM + "get_parameters", names=[name]).values[0]


def described(ros, node):
    names = [n for n in ros.call(ListParameters, node + "list_parameters").result.names
             if n not in ROS_OWN]
    return {d.name: d for d in ros.call(DescribeParameters, node + "describe_parameters",
                                        names=names).descriptors}


@dataclass
class Example:
    trailing: float = 1.0          # a trailing comment [s]
    # a comment above,
    # on two lines
    above: int = 2
    given: str = field(default="", metadata={"description": "from metadata"})  # not this
    bare: float = 3.0
    after_trailing: float = 4.0


def test_descriptions_come_from_the_field_comments():
    d = field_descriptions(Example)
    assert d["trailing"] == "a trailing comment [s]"
    assert d["above"] == "a comment above, on two lines"
    assert d["bare"] == "" and d["after_trailing"] == ""     # no comment of its own


def test_every_parameter_has_a_description_and_says_whether_it_can_be_set(ros, arm_node):
    ranges = described(ros, ARM)
    assert {"rate_hz", "queue_size", "state_rate_hz", "max_action_goals"} <= set(ranges)
    for d in ranges.values():
        assert d.description.replace(READ_ONLY, ""), d.name
        assert d.read_only == (d.name not in SETTABLE), d.name
    assert ranges["accel_time_joint"].floating_point_range[0].to_value == 10.0
    assert ranges["initial_speed_ratio"].integer_range[0].to_value == 100
    # every number has its range (camera_rate_hz, camera_width … had none to describe)
    numbers = (ParameterType.PARAMETER_INTEGER, ParameterType.PARAMETER_DOUBLE)
    assert [d.name for d in ranges.values() if d.type in numbers
            and not (d.floating_point_range or d.integer_range)] == []


def test_an_integer_given_at_start_up_for_a_double_is_that_double(ros, arm_node):
    """Was: `-p clock_rate_hz:=0` ended the node with a type error (a set at run time took it)."""
    for name, x in (("rate_hz", 250.0), ("clock_rate_hz", 100.0)):
        v = get_param(ros, name)
        assert v.type == ParameterType.PARAMETER_DOUBLE and v.double_value == x, name


def test_a_set_takes_effect_as_the_service_would(ros, arm_node):
    """Was: `ros2 param set … max_speed_translation 250` said successful and changed nothing."""
    r = set_param(ros, "max_speed_translation", ParameterType.PARAMETER_INTEGER, 250)  # as typed
    assert r.successful, r.reason
    speed = ros.call(srv.GetMaxSpeedCartesian, ARM + "get_max_speed_cartesian").speed
    assert (speed.translation, speed.rotation) == (250.0, 90.0)
    assert get_param(ros, "max_speed_translation").double_value == 250.0
    r = set_param(ros, "min_accel_time_joint", ParameterType.PARAMETER_DOUBLE, 0.5)
    assert r.successful
    got = ros.call(srv.GetMinAccelTimeJoint, ARM + "get_min_accel_time_joint").acl_time
    assert got == 0.5
    # raised with it (the service's rule), and the parameter shows it
    assert wait_until(lambda: get_param(ros, "accel_time_joint").double_value == 0.5, 10.0)
    box = [-500.0, 900.0, -800.0, 800.0, 0.0, 1500.0]
    assert set_param(ros, "soft_limit_cartesian", ParameterType.PARAMETER_DOUBLE_ARRAY,
                     box).successful
    lim = ros.call(srv.GetSoftLimitCartesian, ARM + "get_soft_limit_cartesian")
    assert (lim.x_limit.lower, lim.x_limit.upper, lim.z_limit.upper) == (-500.0, 900.0, 1500.0)


@pytest.mark.parametrize("name, kind, x, words", [
    ("accel_time_joint", ParameterType.PARAMETER_DOUBLE, 600.0, "10"),
    ("accel_time_cartesian", ParameterType.PARAMETER_DOUBLE, 0.01, "minimum"),
    ("max_speed_translation", ParameterType.PARAMETER_DOUBLE, 5e-324, "1"),
    ("soft_limit_cartesian", ParameterType.PARAMETER_DOUBLE_ARRAY, [0.0] * 6, "above lower"),
    ("soft_limit_cartesian", ParameterType.PARAMETER_DOUBLE_ARRAY, [0.0] * 5, "6 values"),
    ("home_joints_deg", ParameterType.PARAMETER_DOUBLE_ARRAY, [0.0] * 6 + [400.0], "soft limit"),
])
def test_a_bad_value_is_refused_with_the_services_reason(ros, arm_node, name, kind, x, words):
    before = get_param(ros, name)
    r = set_param(ros, name, kind, x)
    assert not r.successful and words in r.reason, r.reason
    assert get_param(ros, name) == before
    assert arm_node.alive()


def test_an_atomic_set_with_a_refused_value_changes_nothing(ros, arm_node):
    """The values before the refused one stayed applied: max_speed_translation became 124 and
    min_accel_time_joint 0.3 though the set answered unsuccessful."""
    names = ["max_speed_translation", "min_accel_time_joint", "accel_time_joint"]
    before = [get_param(ros, n) for n in names]
    speed0 = ros.call(srv.GetMaxSpeedCartesian, ARM + "get_max_speed_cartesian").speed
    r = ros.call(SetParametersAtomically, ARM + "set_parameters_atomically", parameters=[
        Parameter(name="max_speed_translation", value=value(ParameterType.PARAMETER_DOUBLE, 124.0)),
        Parameter(name="min_accel_time_joint", value=value(ParameterType.PARAMETER_DOUBLE, 0.2)),
        Parameter(name="accel_time_joint", value=value(ParameterType.PARAMETER_DOUBLE, 0.1))])
    assert not r.result.successful and "minimum" in r.result.reason, r.result.reason
    speed = ros.call(srv.GetMaxSpeedCartesian, ARM + "get_max_speed_cartesian").speed
    minimum = ros.call(srv.GetMinAccelTimeJoint, ARM + "get_min_accel_time_joint").acl_time
    assert speed.translation == speed0.translation and minimum == before[1].double_value
    assert [get_param(ros, n) for n in names] == before


@pytest.mark.parametrize("name, kind, x", [
    ("queue_size", ParameterType.PARAMETER_INTEGER, 8),
    ("rate_hz", ParameterType.PARAMETER_DOUBLE, 100.0),
    ("gripper_speed", ParameterType.PARAMETER_DOUBLE, 50.0),
    ("state_rate_hz", ParameterType.PARAMETER_DOUBLE, 5.0),
])
def test_a_read_only_parameter_refuses_every_set(ros, arm_node, name, kind, x):
    r = set_param(ros, name, kind, x)
    assert not r.successful and "read-only" in r.reason


def test_vehicle_parameters_are_described_and_read_only(ros, vehicle_node):
    params = described(ros, BASE)
    assert {"rate_hz", "velocity_limit_translation", "jog_timeout"} <= set(params)
    for d in params.values():
        assert d.description.replace(READ_ONLY, "") and d.read_only, d.name
    r = ros.call(SetParameters, BASE + "set_parameters", parameters=[Parameter(
        name="velocity_limit_translation",
        value=value(ParameterType.PARAMETER_DOUBLE, 500.0))]).results[0]
    assert not r.successful and "read-only" in r.reason


def test_the_shipped_parameter_file_lists_every_parameter(ros, arm_node, vehicle_node):
    """config/acti_ros2.yaml lacked clock_rate_hz, wait_feedback_rate_hz and max_wait_goals:
    the README sends users to it for every parameter and its units."""
    import os

    import yaml
    with open(os.path.join(os.path.dirname(__file__), "..", "config", "acti_ros2.yaml")) as f:
        shipped = {k: set(v["ros__parameters"]) for k, v in yaml.safe_load(f).items()}
    arm, base = shipped["/**/acti_middle_node"], shipped["/**/vehicle_node"]
    assert set(described(ros, ARM)) - arm == set()
    # the simulation's parameters are the arm's in the main job (it hosts the simulation)
    assert set(described(ros, BASE)) - base - arm == set()


def test_a_change_through_a_service_shows_in_the_parameter(ros, arm_node):
    r = ros.call(srv.SetMaxSpeedCartesian, ARM + "set_max_speed_cartesian",
                 speed=CartesianSpeed(translation=321.0, rotation=45.0))
    assert r.return_id.id == 0
    assert wait_until(lambda: get_param(ros, "max_speed_rotation").double_value == 45.0, 10.0)
    assert get_param(ros, "max_speed_translation").double_value == 321.0
    limits = [LimitValue(upper=1200.0, lower=-1000.0), LimitValue(upper=1000.0, lower=-1000.0),
              LimitValue(upper=1600.0, lower=-100.0)]
    r = ros.call(srv.SetSoftLimitCartesian, ARM + "set_soft_limit_cartesian",
                 x_limit=limits[0], y_limit=limits[1], z_limit=limits[2])
    assert r.return_id.id == 0
    assert wait_until(lambda: list(get_param(ros, "soft_limit_cartesian").double_array_value)
                      == [-1000.0, 1200.0, -1000.0, 1000.0, -100.0, 1600.0], 10.0)


# a node without /clock: its own cadence must not hang on use_sim_time
quiet_clock_node = node_fixture("acti_middle_node", "clock_rate_hz:=0.0", namespace="/quiet")


def test_use_sim_time_set_at_run_time_without_a_clock_stops_nothing(ros, quiet_clock_node):
    """The state topic, the settings mirrored into parameters and the action feedback run on
    the steady clock: use_sim_time (rclpy's own, settable) with no /clock stopped all three."""
    from acti_msgs.msg import ArmState
    node = "/quiet" + ARM
    r = ros.call(SetParameters, node + "set_parameters", parameters=[Parameter(
        name="use_sim_time", value=ParameterValue(type=ParameterType.PARAMETER_BOOL,
                                                  bool_value=True))]).results[0]
    assert r.successful
    states = []
    sub = ros.node.create_subscription(ArmState, node + "state", states.append, 10)
    try:
        assert ros.spin_until(lambda: len(states) >= 10, 10.0), f"{len(states)} states"
    finally:
        ros.node.destroy_subscription(sub)
    assert ros.call(srv.SetAccelTimeJoint, node + "set_accel_time_joint",
                    acl_time=0.7).return_id.id == 0
    assert wait_until(lambda: ros.call(GetParameters, node + "get_parameters",
                                       names=["accel_time_joint"]).values[0].double_value
                      == 0.7, 10.0)
