"""The arm driven as MoveIt drives it, over DDS against the real node: FollowJointTrajectory goals
sent as MoveIt's simple controller manager sends them (no tolerances, goal_time_tolerance 0, then
the action status), the gripper actions and both streaming topics, with the ACT services acting
on all of them through the one queue. A refused goal's reason is read from /rosout."""
from __future__ import annotations

import math
import re

import numpy as np
import pytest
from acti_msgs import srv
from acti_msgs.msg import LimitValue
from action_msgs.msg import GoalStatus
from builtin_interfaces.msg import Duration
from control_msgs.action import FollowJointTrajectory, GripperCommand, ParallelGripperCommand
from control_msgs.msg import GripperCommand as GripperCommandMsg, JointJog, JointTolerance
from rcl_interfaces.msg import Log
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from acti_sim.world import ARM_JOINTS, GRIPPER_JOINTS
from ros_harness import Actions, node_fixture

# the node runs 4x faster than real time (ros_harness.TEST_RATE): its goals' checks and feedback
# run 4x as often, so that they come as often in simulated time as at the default rate in real time
arm_node = node_fixture("acti_middle_node", "jog_timeout_s:=0.3", "trajectory_feedback_rate_hz:=100.0",
                        "gripper_feedback_rate_hz:=80.0")
ARM = "/acti_middle_node/"
Result = FollowJointTrajectory.Result
TIMEOUT = 60.0


class Robot:
    """The test's view of the arm: services, the controller's action and topics, /clock, /rosout."""

    def __init__(self, ros):
        self.ros = ros
        self.follow = Actions(ros, FollowJointTrajectory, "/arm_controller/follow_joint_trajectory")
        self.gripper = Actions(ros, GripperCommand, "/gripper_controller/gripper_cmd")
        self.parallel = Actions(ros, ParallelGripperCommand,
                                "/parallel_gripper_controller/gripper_cmd")
        self.sim_time = 0.0
        self.log: list[str] = []
        rosout_qos = QoSProfile(depth=1000, durability=DurabilityPolicy.TRANSIENT_LOCAL,
                                reliability=ReliabilityPolicy.RELIABLE)
        node = ros.node
        self._subs = [
            node.create_subscription(Clock, "/clock", self._clock, 10),
            node.create_subscription(Log, "/rosout", self._rosout, rosout_qos)]
        self.trajectory_topic = node.create_publisher(JointTrajectory,
                                                      "/arm_controller/joint_trajectory", 10)
        self.jog_topic = node.create_publisher(JointJog, "/arm_controller/joint_jog", 10)
        assert self.until(lambda: self.sim_time > 0 and self.trajectory_topic
                          .get_subscription_count() and self.jog_topic.get_subscription_count())

    def _clock(self, msg):
        self.sim_time = msg.clock.sec + msg.clock.nanosec * 1e-9

    def _rosout(self, msg):
        if msg.name == "acti_middle_node":
            self.log.append(msg.msg)

    def until(self, predicate, timeout=TIMEOUT):
        return self.ros.spin_until(predicate, timeout)

    def call(self, name, srv_type, **fields):
        return self.ros.call(srv_type, ARM + name, **fields)

    def ready(self):
        self.call("clear_alarms", srv.ClearAlarms)
        self.call("stop", srv.Stop)
        assert self.call("servo_on", srv.ServoON).return_id.id == 0
        assert self.until(lambda: not self.state() & 0x02)

    def state(self):
        return self.call("get_state", srv.GetState).state

    def joints(self):
        return np.radians(self.call("get_feedback_pos_joint", srv.GetFeedbackPosJoint).pos[:7])

    def logged(self, pattern):
        """A line of the node's log on /rosout matches the regular expression `pattern`."""
        return self.until(lambda: any(re.search(pattern, line) for line in self.log), 30.0)


@pytest.fixture(scope="module")
def robot(ros, arm_node):
    return Robot(ros)


def smooth(q0, q1, duration, count=4, names=ARM_JOINTS):
    """A MoveIt-like trajectory: `count` points of a minimum-jerk move from q0 to q1, with the
    velocities and accelerations of its time parameterisation, the first at time 0."""
    q0, q1 = np.asarray(q0, float), np.asarray(q1, float)
    points = []
    for t in np.linspace(0.0, duration, count):
        s = t / duration
        p = 10 * s**3 - 15 * s**4 + 6 * s**5
        v = (30 * s**2 - 60 * s**3 + 30 * s**4) / duration
        a = (60 * s - 180 * s**2 + 120 * s**3) / duration**2
        points.append(JointTrajectoryPoint(
            positions=(q0 + p * (q1 - q0)).tolist(), velocities=(v * (q1 - q0)).tolist(),
            accelerations=(a * (q1 - q0)).tolist(),
            time_from_start=Duration(sec=int(t), nanosec=int(round((t % 1) * 1e9)))))
    return JointTrajectory(joint_names=list(names), points=points)


def moveit_goal(trajectory):
    """As MoveIt sends it: no tolerances, goal_time_tolerance 0."""
    return {"trajectory": trajectory, "goal_time_tolerance": Duration()}


def offset(q, d, joint=0):
    out = np.array(q, float)
    out[joint] += d
    return out


def wait_status(robot, handle, statuses):
    return robot.until(lambda: handle.status in statuses)


def running(robot, handle):
    """Accepted and moving (the state word says so), not over."""
    return robot.until(lambda: bool(robot.state() & 0x02)) and handle.status not in (
        GoalStatus.STATUS_SUCCEEDED, GoalStatus.STATUS_CANCELED, GoalStatus.STATUS_ABORTED)


def long_goal(robot, travel=0.6, duration=8.0):
    """A ready arm following a long goal on joint1: (where it started, the goal's handle)."""
    robot.ready()
    q0 = robot.joints()
    handle = robot.follow.send(**moveit_goal(smooth(q0, offset(q0, travel), duration)))
    assert running(robot, handle)
    return q0, handle


def test_joint_states_carry_every_moving_urdf_joint_on_the_clock(robot):
    """MoveIt's "complete current state": every non-fixed joint of the URDF, stamped with the
    simulated time of /clock."""
    import xml.etree.ElementTree as ET

    from acti_sim.world import URDF_PATH
    moving = {j.get("name") for j in ET.parse(URDF_PATH).getroot().findall("joint")
              if j.get("type") != "fixed"}
    got = []
    sub = robot.ros.node.create_subscription(JointState, "/joint_states", got.append, 10)
    try:
        assert robot.until(lambda: got)
        msg, now = got[-1], robot.sim_time
        assert set(msg.name) == moving and len(msg.position) == len(msg.name)
        assert abs(msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9 - now) < 1.0
    finally:
        robot.ros.node.destroy_subscription(sub)


# --- MoveIt's part -------------------------------------------------------------------------------
def test_a_four_point_trajectory_succeeds_on_time_and_on_target(robot):
    robot.ready()
    q0 = robot.joints()
    q1 = q0 + np.radians([10, -8, 6, 8, -6, 10, 12])
    duration = 2.0
    feedback = []
    start = robot.sim_time
    handle = robot.follow.send(feedback.append, **moveit_goal(smooth(q0, q1, duration)))
    status, result = robot.follow.result(handle)
    took = robot.sim_time - start
    assert status == GoalStatus.STATUS_SUCCEEDED and result.error_code == Result.SUCCESSFUL
    assert "within the goal tolerance" in result.error_string
    assert np.max(np.abs(robot.joints() - q1)) < 0.01
    assert took <= 1.1 * duration + 0.5
    assert len(feedback) >= 2
    fb = feedback[-1].feedback
    assert list(fb.joint_names) == list(ARM_JOINTS)
    assert len(fb.desired.positions) == len(fb.actual.positions) == len(fb.error.positions) == 7
    assert not robot.state() & 0x02


def test_a_new_goal_preempts_the_running_one(robot):
    q0, first = long_goal(robot, 0.5)
    back = smooth(q0, q0, 1.5)
    back.points = back.points[1:]            # from wherever the arm is: no point at time 0
    second = robot.follow.send(**moveit_goal(back))
    status, result = robot.follow.result(first)
    assert status == GoalStatus.STATUS_ABORTED and result.error_code == Result.INVALID_GOAL
    assert "preempted" in result.error_string
    status, result = robot.follow.result(second)
    assert status == GoalStatus.STATUS_SUCCEEDED
    assert np.max(np.abs(robot.joints() - q0)) < 0.01


def test_cancel_decelerates_and_holds(robot):
    q0, handle = long_goal(robot)
    robot.follow.cancel(handle)
    status, result = robot.follow.result(handle)
    assert status == GoalStatus.STATUS_CANCELED and "decelerated" in result.error_string
    assert not robot.state() & 0x02
    held = robot.joints()
    assert 0.0 < held[0] - q0[0] < 0.6
    # held: later measurements are where it stopped
    t = robot.sim_time
    assert robot.until(lambda: robot.sim_time > t + 0.2)
    assert np.max(np.abs(robot.joints() - held)) < 1e-3


@pytest.mark.parametrize("change, words", [
    (lambda tr: setattr(tr, "joint_names", ["joint1", "joint2", "joint3", "joint4", "joint5",
                                            "joint6", "wrist"]), r"unknown joint\(s\) wrist"),
    (lambda tr: setattr(tr.points[-1], "time_from_start", Duration(nanosec=200_000_000)),
     "not strictly increasing"),
    (lambda tr: setattr(tr, "points", []), "no points"),
])
def test_a_goal_the_controller_refuses_is_rejected_and_logged(robot, change, words):
    robot.ready()
    q0 = robot.joints()
    trajectory = smooth(q0, offset(q0, 0.1), 1.0)
    change(trajectory)
    assert not robot.follow.offer(**moveit_goal(trajectory)).accepted
    assert robot.logged(words)


def test_a_limit_violation_is_rejected_naming_joint_point_and_limit(robot):
    robot.ready()
    q0 = robot.joints()
    too_fast = smooth(q0, offset(q0, 1.0, joint=2), 0.5)
    assert not robot.follow.offer(**moveit_goal(too_fast)).accepted
    assert robot.logged(r"joint3 breaks its max speed between .*point 1 .*limit ±1\.7453 rad/s")
    past_limit = smooth(q0, offset(q0, 3.5 - q0[1], joint=1), 20.0)
    assert not robot.follow.offer(**moveit_goal(past_limit)).accepted
    assert robot.logged(r"joint2 breaks its soft limit .*point .*limit \[-2\.0944, 2\.0944\] rad")
    assert not robot.state() & 0x02


def test_act_stop_aborts_the_goal_and_says_so(robot):
    q0, handle = long_goal(robot)
    assert robot.call("stop", srv.Stop).return_id.id == 0
    status, result = robot.follow.result(handle)
    assert status == GoalStatus.STATUS_ABORTED and "discarded by stop" in result.error_string
    assert not robot.state() & 0x02


def test_pause_holds_the_goal_and_resume_finishes_it(robot):
    robot.ready()
    q0 = robot.joints()
    q1 = offset(q0, 0.3)
    handle = robot.follow.send(**moveit_goal(smooth(q0, q1, 2.0)))
    assert running(robot, handle)
    assert robot.call("pause", srv.Pause).return_id.id == 0
    assert robot.until(lambda: robot.state() & 0x12 == 0x10)          # paused, not moving
    held, t = robot.joints(), robot.sim_time
    assert robot.until(lambda: robot.sim_time > t + 0.5)
    assert np.max(np.abs(robot.joints() - held)) < 1e-3
    assert handle.status not in (GoalStatus.STATUS_SUCCEEDED, GoalStatus.STATUS_ABORTED)
    assert robot.call("resume", srv.Resume).return_id.id == 0
    status, result = robot.follow.result(handle)
    assert status == GoalStatus.STATUS_SUCCEEDED
    assert np.max(np.abs(robot.joints() - q1)) < 0.01


def test_servo_off_aborts_the_goal_and_rejects_the_next(robot):
    q0, handle = long_goal(robot)
    assert robot.call("servo_off", srv.ServoOFF).return_id.id == 0
    status, result = robot.follow.result(handle)
    assert status == GoalStatus.STATUS_ABORTED and "servo off" in result.error_string
    q = robot.joints()
    assert not robot.follow.offer(**moveit_goal(smooth(q, q, 1.0))).accepted
    assert robot.logged("servo is off")


def test_a_goal_is_rejected_while_act_moves_are_queued(robot):
    robot.ready()
    assert robot.call("set_speed_joint", srv.SetSpeedJoint, spd_ratio=20).return_id.id == 0
    assert robot.call("move_ptp_joint_rel", srv.MovePTPJointRel,
                      joint_points=[10.0] + [0.0] * 6).return_id.id == 0
    q = robot.joints()
    assert not robot.follow.offer(**moveit_goal(smooth(q, offset(q, 0.1), 1.0))).accepted
    assert robot.logged(r"1 motion\(s\) \(ACT moves, gripper commands\) running or queued")
    robot.call("stop", srv.Stop)


def test_tolerances_abort_with_their_codes(robot):
    """A path tolerance the tracking cannot keep stops the arm; a goal tolerance it cannot reach
    aborts goal_time_tolerance after the end."""
    robot.ready()
    q0 = robot.joints()
    tight = [JointTolerance(name="joint1", position=1e-7)]
    handle = robot.follow.send(trajectory=smooth(q0, offset(q0, 0.3), 2.0), path_tolerance=tight)
    status, result = robot.follow.result(handle)
    assert status == GoalStatus.STATUS_ABORTED
    assert result.error_code == Result.PATH_TOLERANCE_VIOLATED and "joint1 position" in \
        result.error_string
    assert robot.until(lambda: not robot.state() & 0x02)
    q = robot.joints()
    handle = robot.follow.send(trajectory=smooth(q, offset(q, 0.1), 1.0), goal_tolerance=[
        JointTolerance(name="joint2", position=1e-12)], goal_time_tolerance=Duration(
        nanosec=200_000_000))
    status, result = robot.follow.result(handle)
    assert status == GoalStatus.STATUS_ABORTED
    assert result.error_code == Result.GOAL_TOLERANCE_VIOLATED and "joint2" in result.error_string


def test_a_goal_is_rejected_while_a_program_runs(robot):
    from acti_msgs.action import RunProgram
    robot.ready()
    programs = Actions(robot.ros, RunProgram, ARM + "run_program")
    run = programs.send(text="60 DELAY")               # a program that only waits (60 s simulated)
    q = robot.joints()
    assert not robot.follow.offer(**moveit_goal(smooth(q, offset(q, 0.1), 1.0))).accepted
    assert robot.logged("a STROLIC program runs")
    programs.cancel(run)
    assert programs.result(run)[0] == GoalStatus.STATUS_CANCELED
    handle = robot.follow.send(**moveit_goal(smooth(q, offset(q, 0.1), 1.0)))   # then accepted
    assert robot.follow.result(handle)[0] == GoalStatus.STATUS_SUCCEEDED


# --- the gripper -------------------------------------------------------------------------------------
def test_gripper_command_reaches_its_position(robot):
    robot.ready()
    handle = robot.gripper.send(command=GripperCommandMsg(position=0.03, max_effort=10.0))
    status, result = robot.gripper.result(handle)
    assert status == GoalStatus.STATUS_SUCCEEDED and result.reached_goal and not result.stalled
    assert result.position == pytest.approx(0.03, abs=5e-4)
    opening = robot.call("get_feedback_pos_joint", srv.GetFeedbackPosJoint).pos[7]
    assert opening == pytest.approx(60.0, abs=1.0)                   # the ACT getter agrees
    assert not robot.gripper.offer(command=GripperCommandMsg(position=0.5)).accepted
    assert robot.logged("outside the finger's range")


def test_parallel_gripper_command_moves_both_fingers(robot):
    robot.ready()
    handle = robot.parallel.send(command=JointState(name=[GRIPPER_JOINTS[0]], position=[0.01]))
    status, result = robot.parallel.result(handle)
    assert status == GoalStatus.STATUS_SUCCEEDED and result.reached_goal
    assert list(result.state.name) == list(GRIPPER_JOINTS)
    assert result.state.position.tolist() == pytest.approx([0.01, 0.01], abs=5e-4)
    bad = JointState(name=list(GRIPPER_JOINTS), position=[0.01, 0.02])
    assert not robot.parallel.offer(command=bad).accepted
    assert robot.logged("mimic each other")


# --- streaming ---------------------------------------------------------------------------------------
def test_the_trajectory_topic_replaces_what_runs(robot):
    robot.ready()
    q0 = robot.joints()
    first = smooth(q0, offset(q0, 0.5), 3.0)
    first.points = first.points[1:]
    robot.trajectory_topic.publish(first)
    assert robot.until(lambda: robot.joints()[0] > q0[0] + 0.05)
    second = smooth(q0, offset(q0, -0.2), 2.0)
    second.points = second.points[1:]
    robot.trajectory_topic.publish(second)
    assert robot.until(lambda: not robot.state() & 0x02 and
                       abs(robot.joints()[0] - (q0[0] - 0.2)) < 0.01)


def jog(velocity, joint="joint1"):
    return JointJog(joint_names=[joint], velocities=[velocity])


def test_jog_moves_while_jogs_come_and_stops_after_the_deadman(robot):
    robot.ready()
    q0 = robot.joints()
    robot.jog_topic.publish(jog(0.3))
    assert robot.until(lambda: robot.state() & 0x02)
    t0 = robot.sim_time
    # a stream of jogs keeps it moving; then none: it stops after the jog timeout (0.3 s)
    while robot.sim_time < t0 + 1.0:
        robot.jog_topic.publish(jog(0.3))
        robot.until(lambda: False, 0.05)
    assert robot.state() & 0x02
    assert robot.until(lambda: not robot.state() & 0x02)
    moved = robot.joints()[0] - q0[0]
    assert 0.3 < moved < 0.3 * (robot.sim_time - t0 + 0.5)


def test_jog_stays_inside_the_soft_limits_and_stop_ends_it(robot):
    robot.ready()
    limits = robot.call("get_soft_limit_joint", srv.GetSoftLimitJoint).soft_limit
    limits[0] = LimitValue(upper=math.degrees(robot.joints()[0]) + 5.0, lower=-170.0)
    assert robot.call("set_soft_limit_joint", srv.SetSoftLimitJoint,
                      soft_limit=limits).return_id.id == 0
    upper = math.radians(robot.call("get_soft_limit_joint", srv.GetSoftLimitJoint)
                         .soft_limit[0].upper)
    robot.jog_topic.publish(JointJog(joint_names=["joint1"], velocities=[5.0], duration=5.0))
    assert robot.until(lambda: robot.state() & 0x02)
    assert robot.until(lambda: not robot.state() & 0x02)
    assert upper - 0.01 < robot.joints()[0] <= upper
    assert robot.call("get_active_alarm", srv.GetActiveAlarm).alarms == []
    # a jog away from the limit, ended by the ACT stop
    robot.jog_topic.publish(JointJog(joint_names=["joint1"], velocities=[-0.5], duration=5.0))
    assert robot.until(lambda: robot.state() & 0x02)
    assert robot.call("stop", srv.Stop).return_id.id == 0
    assert robot.until(lambda: not robot.state() & 0x02)
    assert robot.joints()[0] > upper - 0.5
