"""tools/ros2_lite.py fills requests as the real `ros2` CLI does (ROS-free: no DDS)."""
import importlib.util
import os

import pytest

from acti_bringup.harness import ROOT

_spec = importlib.util.spec_from_file_location("ros2_lite",
                                               os.path.join(ROOT, "tools", "ros2_lite.py"))
ros2_lite = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(ros2_lite)


def test_a_request_is_filled_from_yaml_with_integers_for_floats():
    cls = ros2_lite.interface("acti_msgs/srv/VehicleMoveLinearAbs")
    req = ros2_lite.request(cls.Request, "{pos: {x: 1000, y: 500.5, theta: 0}}")
    assert (req.pos.x, req.pos.y, req.pos.theta) == (1000.0, 500.5, 0.0)
    joints = ros2_lite.request(ros2_lite.interface("acti_msgs/srv/MovePTPJointAbs").Request,
                               "{joint_points: [10, 20.5]}")
    assert list(joints.joint_points) == [10.0, 20.5]


def test_a_sequence_of_messages_is_filled_item_by_item():
    twist = ros2_lite.request(ros2_lite.interface("geometry_msgs/msg/Twist"),
                              "{linear: {x: 0.2}, angular: {z: 0.3}}")
    assert (twist.linear.x, twist.angular.z) == (0.2, 0.3)
    event = ros2_lite.request(ros2_lite.interface("rcl_interfaces/msg/ParameterEvent"),
                              "{node: /n, new_parameters: [{name: a}, {name: b}]}")
    assert [p.name for p in event.new_parameters] == ["a", "b"]
    assert ros2_lite.as_plain(event)["new_parameters"][1]["name"] == "b"


@pytest.mark.parametrize("type_name, values, why", [
    ("acti_msgs/srv/VehicleMoveForward", "{y: 1.0}", "has no field 'y'"),
    ("acti_msgs/srv/VehicleMoveForward", "{x: fast}", "cannot be 'fast'"),
    ("acti_msgs/srv/VehicleMoveForward", "[1, 2]", "must be a mapping"),
    ("acti_msgs/srv/VehicleMoveForward", "{x: [1", "not YAML"),
    ("acti_msgs/srv/MovePTPJointAbs", "{joint_points: 3}", "is a sequence"),
    ("acti_msgs/srv/NoSuchThing", "{}", "not known here"),
    ("acti_msgs/NoSuchThing", "{}", "must be pkg/msg|srv|action/Name"),
])
def test_what_cannot_be_sent_is_one_line_that_says_why(type_name, values, why):
    with pytest.raises(ros2_lite.Usage, match=why.replace("|", r"\|").replace("[", r"\[")):
        cls = ros2_lite.interface(type_name)
        ros2_lite.request(cls.Request, values)
