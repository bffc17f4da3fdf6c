"""The main job: one process hosting both nodes on one shared world answers both get_state."""
from acti_msgs import srv

from ros_harness import node_fixture

robot = node_fixture("acti_bringup", "velocity_limit_translatoin:=5.0")


def test_both_nodes_answer_get_state(ros, robot):
    assert ros.call(srv.GetState, "/acti_middle_node/get_state").return_id.id == 0
    r = ros.call(srv.VehicleGetState, "/vehicle_node/get_state")
    assert r.success and (r.state, r.msg) == (0x019, "Unpowered")


def test_a_misspelt_parameter_is_named_once(robot):
    """rclpy ignores a setting no node has without a word; a misspelt safety limit went unseen."""
    warned = [line for line in robot.log().splitlines() if "unknown parameters" in line]
    assert len(warned) == 1 and "velocity_limit_translatoin" in warned[0], robot.log()
