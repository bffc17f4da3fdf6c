"""A fleet in one domain: two main jobs in namespaces /robot1 and /robot2, each moved over DDS
without touching the other, each publishing its own simulated time and joints in its namespace
(published only while subscribed: these subscriptions start them)."""
import os
import re

from acti_msgs import srv
from diagnostic_msgs.msg import DiagnosticArray
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState

from ros_harness import TEST_RATE, NodeProcess, node_fixture, wait_until

# the project's parameter file (its nodes' keys match them in any namespace), one value changed
with open(os.path.join(os.path.dirname(__file__), "..", "config", "acti_ros2.yaml")) as f:
    PARAMS = f.read().replace("velocity_limit_translation: 1000.0", "velocity_limit_translation: 800.0")
robot1 = node_fixture("acti_bringup", namespace="/robot1", params_yaml=PARAMS)
robot2 = node_fixture("acti_bringup", namespace="/robot2")

TARGET = [15.0, 25.0, -10.0, -70.0, 20.0, 45.0, -30.0]


def arm(ns: str, op: str) -> str:
    return f"{ns}/acti_middle_node/{op}"


def base(ns: str, op: str) -> str:
    return f"{ns}/vehicle_node/{op}"


def joints(ros, ns):
    return ros.call(srv.GetFeedbackPosJoint, arm(ns, "get_feedback_pos_joint")).pos


def position(ros, ns):
    p = ros.call(srv.VehicleGetPosition, base(ns, "get_position")).pos
    return p.x, p.y, p.theta


def test_each_robot_moves_without_touching_the_other(ros, robot1, robot2):
    joints2, pos1 = joints(ros, "/robot2"), position(ros, "/robot1")
    assert ros.call(srv.ServoON, arm("/robot1", "servo_on")).return_id.id == 0
    assert ros.call(srv.SetSpeedJoint, arm("/robot1", "set_speed_joint"),
                    spd_ratio=60).return_id.id == 0
    assert ros.call(srv.MovePTPJointAbs, arm("/robot1", "move_ptp_joint_abs"),
                    joint_points=TARGET).return_id.id == 0
    assert ros.call(srv.VehicleSetPower, base("/robot2", "set_power"), on_off=True).success
    assert ros.call(srv.VehicleSetServo, base("/robot2", "set_servo"), on_off=True).success
    assert ros.call(srv.VehicleMoveForward, base("/robot2", "move_forward"), x=300.0).success

    assert wait_until(lambda: ros.call(srv.GetState, arm("/robot1", "get_state")).state & 0x02 == 0
                      and ros.call(srv.VehicleGetState, base("/robot2", "get_state")).state == 0x010,
                      30.0)
    assert max(abs(a - b) for a, b in zip(joints(ros, "/robot1"), TARGET)) < 0.01
    x, y, _ = position(ros, "/robot2")
    assert abs(x - 300.0) < 5.0 and abs(y) < 5.0
    # the other robot of each pair did not move and was not switched on
    assert max(abs(a - b) for a, b in zip(joints(ros, "/robot2"), joints2)) < 0.01
    assert max(abs(a - b) for a, b in zip(position(ros, "/robot1"), pos1)) < 0.5
    assert ros.call(srv.GetState, arm("/robot2", "get_state")).state & 0x01 == 0      # servo off
    r = ros.call(srv.VehicleGetState, base("/robot1", "get_state"))
    assert (r.state, r.msg) == (0x019, "Unpowered")


def test_a_namespaced_robot_takes_its_parameter_file(ros, robot1, robot2):
    """The file's keys are /**/vehicle_node …: plain vehicle_node matched only the root namespace,
    and a fleet robot silently ran on the defaults."""
    limit = lambda ns: ros.call(srv.VehicleGetVelocityLimit,  # noqa: E731
                                base(ns, "get_velocity_limit")).vel_limit_t
    assert (limit("/robot1"), limit("/robot2")) == (800.0, 1000.0)


STAMPED = {"clock": (Clock, lambda m: m.clock), "joint_states": (JointState, lambda m: m.header.stamp)}


def test_each_robot_publishes_its_own_clock_and_joints_in_its_namespace(ros, robot1, robot2):
    got: dict[str, list[float]] = {}
    subs = []
    for ns in ("/robot1", "/robot2"):
        for topic, (msg_type, stamp_of) in STAMPED.items():
            times = got[f"{ns}/{topic}"] = []
            subs.append(ros.node.create_subscription(
                msg_type, f"{ns}/{topic}", lambda m, times=times, stamp_of=stamp_of:
                times.append(stamp_of(m).sec + stamp_of(m).nanosec * 1e-9), 10))
    try:
        assert ros.spin_until(lambda: all(len(t) >= 20 for t in got.values()), 30.0)
        for stamps in got.values():
            assert stamps == sorted(stamps) and stamps[-1] > stamps[0]
        assert ros.node.count_publishers("/clock") == 0
        assert ros.node.count_publishers("/joint_states") == 0
    finally:
        for s in subs:
            ros.node.destroy_subscription(s)


def test_the_shared_diagnostics_name_each_robot(ros, robot1, robot2):
    names: set[str] = set()
    sub = ros.node.create_subscription(
        DiagnosticArray, "/diagnostics",
        lambda m: names.update((s.name, s.hardware_id) for s in m.status), 10)
    try:
        want = {(f"robot{n}/vehicle_node: {what}", f"robot{n}/base")
                for n in (1, 2) for what in ("battery", "alarms")}
        assert ros.spin_until(lambda: want <= names, 30.0), names
    finally:
        ros.node.destroy_subscription(sub)


def test_a_second_job_in_a_robots_namespace_refuses_to_start(robot1, robot2, tmp_path):
    """Exit status 2 and one line: which names, and how to start it all the same."""
    twin = NodeProcess("acti_bringup", str(tmp_path / "twin.log"), TEST_RATE,
                       "view_enabled:=false", namespace="/robot2")
    try:
        assert twin.proc.wait(timeout=120) == 2, twin.log()
    finally:
        twin.stop()
    fatal = [line for line in twin.log().splitlines() if line.startswith("[FATAL]")]
    assert len(fatal) == 1 and "Traceback" not in twin.log(), twin.log()
    # the names discovery found within its second (all three, as a rule; on a busy machine, some)
    assert re.search(r"cannot start: /robot2/(acti_middle_node|vehicle_node|acti_view)"
                     r"(, /robot2/(vehicle_node|acti_view))* already served in ROS_DOMAIN_ID=",
                     fatal[0]), fatal[0]
    assert "-r __ns:=" in fatal[0] and "allow_namesakes:=true" in fatal[0], fatal[0]


def test_a_second_job_allowed_in_a_robots_namespace_is_reported(ros, robot1, robot2, tmp_path):
    """It starts with allow_namesakes (the graph can list a job that has just ended), and both
    say what is wrong."""
    twin = NodeProcess("acti_bringup", str(tmp_path / "twin.log"), TEST_RATE,
                       "view_enabled:=false", "allow_namesakes:=true", namespace="/robot2")
    try:
        said = "another job runs as /robot2/vehicle_node"
        assert wait_until(lambda: said in twin.log() and said in robot2.log(), 30.0), twin.log()
    finally:
        twin.stop()


def test_each_robots_controllers_are_in_its_namespace(ros, robot1, robot2):
    """MoveIt's controllers of a robot of the fleet: relative names, prefixed by its namespace."""
    from rclpy.action import get_action_names_and_types
    want = {f"/robot{n}/{name}" for n in (1, 2) for name in (
        "arm_controller/follow_joint_trajectory", "gripper_controller/gripper_cmd",
        "parallel_gripper_controller/gripper_cmd")}
    topics = {"/robot1/arm_controller/joint_jog": ["control_msgs/msg/JointJog"],
              "/robot2/arm_controller/joint_trajectory": ["trajectory_msgs/msg/JointTrajectory"]}
    assert wait_until(lambda: want <= dict(get_action_names_and_types(ros.node)).keys(), 30.0)
    assert wait_until(lambda: topics.items() <= dict(ros.node.get_topic_names_and_types()).items(),
                      30.0)
