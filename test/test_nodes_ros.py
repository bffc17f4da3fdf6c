"""Both nodes as real processes over DDS: the first vertical slice end to end."""
import math

import pytest
from acti_msgs import srv

from ros_harness import node_fixture, wait_until

arm_node = node_fixture("acti_middle_node")
vehicle_node = node_fixture("vehicle_node")

ARM = "/acti_middle_node/"
BASE = "/vehicle_node/"
TARGET = [15.0, 25.0, -10.0, -70.0, 20.0, 45.0, -30.0]


def arm_state(ros):
    return ros.call(srv.GetState, ARM + "get_state").state


def test_arm_moves_ptp_to_target_within_a_hundredth_degree(ros, arm_node):
    assert ros.call(srv.MovePTPJointAbs, ARM + "move_ptp_joint_abs",
                    joint_points=TARGET).return_id.id == -4            # servo off
    assert ros.call(srv.ServoON, ARM + "servo_on").return_id.id == 0
    assert ros.call(srv.SetSpeedJoint, ARM + "set_speed_joint", spd_ratio=60).return_id.id == 0
    r = ros.call(srv.MovePTPJointAbs, ARM + "move_ptp_joint_abs", joint_points=TARGET)
    assert r.return_id.id == 0 and r.motion_id >= 1
    assert arm_state(ros) & 0x02
    assert wait_until(lambda: not arm_state(ros) & 0x02, 20.0)
    pos = ros.call(srv.GetFeedbackPosJoint, ARM + "get_feedback_pos_joint").pos
    assert max(abs(a - b) for a, b in zip(pos, TARGET)) < 0.01


@pytest.mark.parametrize("fields, code", [
    (dict(joint_points=[1.0, 2.0]), -3),
    (dict(joint_points=[0.0, 0.0, math.nan, 0.0, 0.0, 0.0, 0.0]), -3),
    (dict(joint_points=[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, math.inf]), -3),
    (dict(joint_points=[0.0, 0.0, 0.0, 500.0, 0.0, 0.0, 0.0]), -3),
])
def test_arm_bad_inputs_get_value_err_and_node_stays_up(ros, arm_node, fields, code):
    ros.call(srv.ServoON, ARM + "servo_on")
    r = ros.call(srv.MovePTPJointAbs, ARM + "move_ptp_joint_abs", **fields)
    assert r.return_id.id == code and r.return_id.comment
    assert ros.call(srv.SetSpeedJoint, ARM + "set_speed_joint", spd_ratio=101).return_id.id == -3
    assert arm_node.alive()


def test_arm_servo_off(ros, arm_node):
    assert ros.call(srv.ServoOFF, ARM + "servo_off").return_id.id == 0
    assert arm_state(ros) & 0x01 == 0


def test_base_moves_forward_500_mm(ros, vehicle_node):
    r = ros.call(srv.VehicleMoveForward, BASE + "move_forward", x=500.0)
    assert not r.success and "Unpowered" in r.message
    assert ros.call(srv.VehicleSetPower, BASE + "set_power", on_off=True).success
    assert ros.call(srv.VehicleSetServo, BASE + "set_servo", on_off=True).success
    r = ros.call(srv.VehicleGetState, BASE + "get_state")
    assert (r.state, r.msg) == (0x010, "Ready")
    assert ros.call(srv.VehicleMoveForward, BASE + "move_forward", x=500.0).success
    assert wait_until(lambda: ros.call(srv.VehicleGetState, BASE + "get_state").state == 0x010,
                      20.0)
    pos = ros.call(srv.VehicleGetPosition, BASE + "get_position").pos
    assert abs(pos.x - 500.0) < 5.0 and abs(pos.y) < 5.0


def test_base_bad_distance(ros, vehicle_node):
    r = ros.call(srv.VehicleMoveForward, BASE + "move_forward", x=math.nan)
    assert not r.success and "finite" in r.message
    assert vehicle_node.alive()
