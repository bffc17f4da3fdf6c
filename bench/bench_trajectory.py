"""Trajectory figures (arm_controller, docs/moveit.md):

1. Tracking: a MoveIt-like trajectory (quintic, 4 points through 3 postures) at 50 % of the rated
   joint speeds, run through the arm's queue in the simulation; the measured joints after every
   control step against the interpolated reference at that step. Goal: max |error| <= 0.5 degree.
2. Goal accept round trip over DDS: FollowJointTrajectory goals to the node (validated, planned,
   limit-checked and queued, each preempting the one before) against a bare action server of the
   same type that accepts at once (bench.trigger_server follow), interleaved in the same run.
Prints figures only (no timing asserts)."""
import math

import numpy as np
from common import RosClient, interleaved, row, running, simulated_arm

from acti_msgs import srv
from builtin_interfaces.msg import Duration
from control_msgs.action import FollowJointTrajectory
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from acti_bringup.harness import Actions
from acti_motion.trajectory.follow import ArmTrajectories
from acti_motion.trajectory.validation import RequestedPoint, RequestedTrajectory, validate
from acti_sim.world import ARM_JOINTS

START = (0.0, 45.0, 0.0, -90.0, 0.0, 45.0, 0.0)
WAYPOINTS_DEG = ((40.0, 15.0, -30.0, -60.0, 40.0, 20.0, 60.0), (-20.0, 60.0, 25.0, -110.0, -30.0, 70.0, -40.0))
SPEED_SHARE = 0.5
MIN_JERK_PEAK = 1.875         # peak speed / mean speed of a minimum-jerk move
N = 200


def min_jerk(q0, q1, duration, t):
    s = t / duration
    d = q1 - q0
    return (q0 + d * (10 * s**3 - 15 * s**4 + 6 * s**5),
            d * (30 * s**2 - 60 * s**3 + 30 * s**4) / duration,
            d * (60 * s - 180 * s**2 + 120 * s**3) / duration**2)


def tracking() -> None:
    world, executor, arm = simulated_arm(START, 50)
    rated = np.radians(arm.max_speed_joint)
    postures = [np.radians(START), *(np.radians(w) for w in WAYPOINTS_DEG), np.radians(START)]
    points, t0 = [], 0.0
    for q0, q1 in zip(postures[:-1], postures[1:]):
        # each leg at SPEED_SHARE of the rated speed of the joint that limits it
        duration = float(np.max(MIN_JERK_PEAK * np.abs(q1 - q0) / (SPEED_SHARE * rated)))
        for t in np.linspace(0.0, duration, 4)[(1 if points else 0):]:
            q, v, a = min_jerk(q0, q1, duration, t)
            points.append(RequestedPoint(t0 + t, q.tolist(), v.tolist(), a.tolist()))
        t0 += duration
    follower = ArmTrajectories(arm)
    _, motion = follower.follow(validate(RequestedTrajectory(list(ARM_JOINTS), points),
                                         ARM_JOINTS, follower.now()), "bench")
    device, errors, speeds = arm.device, [], []
    while device.busy:
        executor.step()
        if device.current is not None:
            ref = motion.state(device.t)
            errors.append(np.abs(world.arm_positions() - ref.positions))
            speeds.append(np.abs(ref.velocities) / rated)
    errors = np.degrees(np.array(errors))
    print(f"tracking: {len(points)} points, {motion.duration:.2f} s, {len(errors)} control steps "
          f"at {1 / executor.dt:.0f} Hz; peak reference speed {100 * np.max(speeds):.0f} % of the "
          "rated speed")
    print(f"  max |error| {np.max(errors):.4f} degree (goal <= 0.5), per joint: "
          + " ".join(f"J{j + 1} {e:.4f}" for j, e in enumerate(np.max(errors, axis=0)))
          + f";  rms {math.sqrt(np.mean(errors ** 2)):.4f} degree")


def accept_round_trip() -> None:
    ros = RosClient()
    with running("bench.trigger_server", args=("follow",)), running("acti_middle_node"):
        ros.call(srv.ServoON, "/acti_middle_node/servo_on")
        node = Actions(ros, FollowJointTrajectory, "/arm_controller/follow_joint_trajectory")
        bare = Actions(ros, FollowJointTrajectory, "/bare_follow/follow_joint_trajectory")
        q = np.radians(ros.call(srv.GetFeedbackPosJoint,
                                "/acti_middle_node/get_feedback_pos_joint").pos[:7])
        # hold where it is for a second: each goal preempts the one before, from where it is
        goal = FollowJointTrajectory.Goal(trajectory=JointTrajectory(
            joint_names=list(ARM_JOINTS), points=[JointTrajectoryPoint(
                positions=q.tolist(), velocities=[0.0] * 7, time_from_start=Duration(sec=1))]))

        def accept(actions: Actions):
            def send():
                handle = actions.spin(actions.client.send_goal_async(goal))
                assert handle.accepted
            return send
        samples = interleaved([("bare FollowJointTrajectory", accept(bare)),
                               ("arm_controller goal", accept(node))], N)
    print("\ngoal accept round trip (send_goal to the goal response), interleaved with a bare "
          "action server of the same type (rclpy SingleThreadedExecutor, accepts at once)")
    print(row("bare FollowJointTrajectory", samples["bare FollowJointTrajectory"]))
    print(row("arm_controller goal", samples["arm_controller goal"],
              samples["bare FollowJointTrajectory"]))
    ros.close()


if __name__ == "__main__":
    tracking()
    accept_round_trip()
