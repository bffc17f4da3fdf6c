"""Which plane serves what: an operation its core does not mark as planning
(`acti_motion.replies.plans`) is served on the control plane, so it must never wait for a plan
under way. Each such operation of both cores, called with a default request while another
thread holds what planning holds, answers at once."""
from __future__ import annotations

import threading
from contextlib import contextmanager
from typing import Iterator

import pytest

from acti_bringup.serving.conversions import request_reader
from acti_middle_node.operations import OPERATIONS as ARM_OPERATIONS
from vehicle_node.operations import OPERATIONS as BASE_OPERATIONS
from arm_fixtures import arm  # noqa: F401
from vehicle_fixtures import base  # noqa: F401
from sim_fixtures import executor  # noqa: F401

ANSWER_S = 2.0


@contextmanager
def held(lock) -> Iterator[None]:
    """`lock` held by another thread (as a plan under way holds it) until the block ends."""
    taken, done = threading.Event(), threading.Event()

    def hold() -> None:
        with lock:
            taken.set()
            done.wait()
    holder = threading.Thread(target=hold, daemon=True)
    holder.start()
    assert taken.wait(ANSWER_S)
    try:
        yield
    finally:
        done.set()
        holder.join(ANSWER_S)


def unmarked(core, operations) -> list:
    return [op for op in operations if not getattr(getattr(core, op.name), "plans", False)]


def answers_while(lock, core, operations) -> list[str]:
    """The names of the unmarked operations that did not answer within ANSWER_S while `lock` was
    held elsewhere."""
    late = []
    with held(lock):
        for op in unmarked(core, operations):
            fields = request_reader(op.srv_type.Request)(op.srv_type.Request())
            caller = threading.Thread(target=getattr(core, op.name), kwargs=fields, daemon=True)
            caller.start()
            caller.join(ANSWER_S)
            if caller.is_alive():
                late.append(op.name)
    return late


def test_the_base_control_plane_never_waits_for_a_plan(base):  # noqa: F811
    assert answers_while(base.planning, base, BASE_OPERATIONS) == []


def test_the_arm_control_plane_never_waits_for_a_plan(arm):  # noqa: F811
    assert answers_while(arm.device._accept, arm, ARM_OPERATIONS) == []


@pytest.mark.parametrize("core, operations, expected", [
    ("base", BASE_OPERATIONS, {"set_acceleration", "set_position", "set_joystick"}),
    ("arm", ARM_OPERATIONS, {"go_home", "open_gripper", "close_gripper", "move_gripper"}),
])
def test_moves_and_what_retimes_or_reframes_them_are_marked_as_planning(request, core,
                                                                       operations, expected):
    core = request.getfixturevalue(core)
    marked = {op.name for op in operations if getattr(getattr(core, op.name), "plans", False)}
    moves = {op.name for op in operations if op.name.startswith("move_")}
    assert marked == moves | expected
