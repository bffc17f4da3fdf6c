"""The main job: one process hosting both nodes on one shared world answers both get_state."""
from acti_msgs import srv

from ros_harness import node_fixture

robot = node_fixture("acti_bringup")


def test_both_nodes_answer_get_state(ros, robot):
    assert ros.call(srv.GetState, "/acti_middle_node/get_state").return_id.id == 0
    r = ros.call(srv.VehicleGetState, "/vehicle_node/get_state")
    assert r.success and (r.state, r.msg) == (0x019, "Unpowered")
