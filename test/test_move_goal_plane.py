"""The arm's ~/move goal on a goal plane of its own (in this process, over DDS): its move plans,
and waits for another's plan, off that plane's one thread, so the other goals are served
meanwhile (a waiting action does not hold an executor thread)."""
from __future__ import annotations

import threading

import pytest
from acti_msgs.action import Move, WaitMotion
from rclpy.executors import SingleThreadedExecutor

from acti_bringup.serving.adapter import Plane
from acti_bringup.serving.spinning import SpinLoop
from acti_middle_node.actions import ActionConfig, MotionActions
from arm_fixtures import arm  # noqa: F401
from ros_harness import Actions
from sim_fixtures import executor  # noqa: F401

ANSWER_S = 5.0


@pytest.fixture
def goals(ros, arm, executor):  # noqa: F811
    """The arm's actions on a goal plane served by a thread of its own, as in the node; the
    simulation on its thread."""
    executor.start()
    owner = ros.rclpy.create_node("acti_middle_node")
    plane = Plane(owner, "goals")
    actions = MotionActions(plane, arm, ActionConfig())
    spinner = SingleThreadedExecutor()
    spinner.add_node(plane)
    loop = SpinLoop(spinner, "ros-goals").start()
    yield plane
    loop.stop()
    spinner.shutdown()
    del actions
    plane.destroy_node()
    owner.destroy_node()
    executor.shutdown()


def test_a_move_goal_waiting_for_another_plan_leaves_the_goal_plane_free(ros, arm, goals):  # noqa: F811
    moves = Actions(ros, Move, goals.name("move"))
    waits = Actions(ros, WaitMotion, goals.name("wait_motion"))
    taken, release = threading.Event(), threading.Event()

    def plan_elsewhere() -> None:                 # a long plan under way (its accept lock)
        with arm.device._accept:
            taken.set()
            release.wait(30.0)
    holder = threading.Thread(target=plan_elsewhere, daemon=True)
    holder.start()
    assert taken.wait(ANSWER_S)
    try:
        move = moves.send(kind="move_ptp_joint_rel", joint_points=[5.0] + [0.0] * 6)
        handle = waits.client.send_goal_async(WaitMotion.Goal(motion_id=0))
        assert ros.wait(handle, ANSWER_S), "the goal plane waited for the move's plan"
        status, result = waits.result(handle.result())
        assert result.completed
    finally:
        release.set()
        holder.join(ANSWER_S)
    _, result = moves.result(move)
    assert result.return_id.id == 0 and result.motion_id == 1
