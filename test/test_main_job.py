"""The main job: one process hosting both nodes on one shared world answers both get_state."""
import re

from acti_msgs import srv

from ros_harness import node_fixture, wait_until

robot = node_fixture("acti_bringup", "velocity_limit_translatoin:=5.0")


def test_both_nodes_answer_get_state(ros, robot):
    assert ros.call(srv.GetState, "/acti_middle_node/get_state").return_id.id == 0
    r = ros.call(srv.VehicleGetState, "/vehicle_node/get_state")
    assert r.success and (r.state, r.msg) == (0x019, "Unpowered")


def test_a_misspelt_parameter_is_named_once(robot):
    """rclpy ignores a setting no node has without a word; a misspelt safety limit went unseen."""
    warned = [line for line in robot.log().splitlines() if "unknown parameters" in line]
    assert len(warned) == 1 and "velocity_limit_translatoin" in warned[0], robot.log()


def test_ready_is_said_once_it_serves_with_the_view_url_and_how_to_stop(robot):
    """`make run` printed 1,770 lines of CMake and nothing said when the nodes were ready."""
    assert wait_until(lambda: "READY:" in robot.log(), 60.0), robot.log()
    ready = [line for line in robot.log().splitlines() if "READY:" in line]
    assert len(ready) == 1 and ready[0].startswith("[INFO]"), robot.log()
    view = re.search(r"live view: (http://\S+)", robot.log()).group(1)
    assert ready[0].endswith(f"READY: /acti_middle_node, /vehicle_node, /acti_view serving | "
                             f"live view: {view} | Ctrl-C to stop"), ready[0]
    assert all(line.startswith("[") for line in robot.log().splitlines() if line), robot.log()
