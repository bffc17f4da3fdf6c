"""ArmCore in the real simulation, without ROS: state word, checks, PTP accuracy, queue."""
import math

import numpy as np
import pytest

from acti_motion.arm.core import ArmConfig, ArmCore
from acti_motion.replies import ReturnCode
from sim_fixtures import executor, run_until  # noqa: F401

TARGET = [10.0, 20.0, 30.0, -40.0, 50.0, 60.0, 70.0]


@pytest.fixture
def arm(executor):  # noqa: F811
    return ArmCore(executor, ArmConfig(queue_size=3))


def ready(arm):
    assert arm.servo_on().ok and arm.set_speed_joint(100).ok


def test_servo_off_refuses_motion(arm):
    r = arm.move_ptp_joint_abs(TARGET)
    assert r.code == ReturnCode.NOT_SV_ON_ERR and "servo" in r.comment


def test_speed_starts_at_zero_and_refuses_motion(arm):
    arm.servo_on()
    r = arm.move_ptp_joint_abs(TARGET)
    assert r.code == ReturnCode.STATUS_ERR and "set_speed_joint" in r.comment


@pytest.mark.parametrize("ratio", [101, 1000, -1])
def test_speed_ratio_out_of_range(arm, ratio):
    r = arm.set_speed_joint(ratio)
    assert r.code == ReturnCode.VALUE_ERR and "100" in r.comment
    assert arm.speed_joint == 0


@pytest.mark.parametrize("points, words", [
    ([1.0] * 6, "7 values"), ([1.0] * 8, "7 values"), ([], "7 values"),
    ([0, 0, 0, math.nan, 0, 0, 0], "finite"), ([0, math.inf, 0, 0, 0, 0, 0], "finite"),
    ([0, 0, 0, 0, 0, 0, 400.0], "soft limit"),
])
def test_bad_joint_targets(arm, points, words):
    ready(arm)
    r = arm.move_ptp_joint_abs(points)
    assert r.code == ReturnCode.VALUE_ERR and words in r.comment
    assert arm.device.queue_length == 0


def test_ptp_reaches_target_with_joints_arriving_together(arm, executor):  # noqa: F811
    ready(arm)
    assert arm.move_ptp_joint_abs(TARGET).ok
    assert arm.state_word() & 0x03 == 0x03
    start = np.degrees(executor.world.arm_positions())
    way = np.subtract(TARGET, start)
    moving = np.abs(way) > 1.0
    remaining = []

    def record():
        q = np.degrees(executor.world.arm_positions())
        remaining.append(((TARGET - q) / np.where(moving, way, 1.0))[moving])
        return not arm.device.busy
    run_until(executor, record, 10.0)
    for _ in range(120):
        executor.step()
    pos = arm.get_feedback_pos_joint().values["pos"]
    assert len(pos) == 8
    assert np.max(np.abs(np.subtract(pos[:7], TARGET))) < 0.01
    # synchronized: at every instant all joints have covered the same fraction of their way
    spread = [np.ptp(r) for r in remaining]
    assert max(spread) < 0.02
    assert arm.state_word() == 0x01


def test_full_queue_refuses_and_keeps_what_is_queued(arm):
    ready(arm)
    for i in range(3):
        assert arm.move_ptp_joint_abs([i + 1.0] * 7).ok
    assert arm.state_word() & 0x08
    r = arm.move_ptp_joint_abs(TARGET)
    assert r.code == ReturnCode.FULL_MOTION_QUEUE_ERR and "full" in r.comment
    # a value no start makes valid is VALUE_ERR, full queue or not
    r = arm.move_ptp_joint_rel([1e308] * 7)
    assert r.code == ReturnCode.VALUE_ERR and "J1 by 1e+308°" in r.comment, r.comment
    assert arm.device.queue_length == 3


def test_move_to_where_it_is_finishes_at_once(arm, executor):  # noqa: F811
    ready(arm)
    here = list(ArmConfig().initial_joints_deg)
    assert arm.move_ptp_joint_abs(here).ok
    assert run_until(executor, lambda: not arm.device.busy, 1.0) < 0.02


def test_servo_off_while_moving_stops_first(arm, executor):  # noqa: F811
    ready(arm)
    assert arm.move_ptp_joint_abs(TARGET).ok
    for _ in range(120):
        executor.step()
    assert arm.servo_off().ok
    assert arm.device.queue_length == 0
    took = run_until(executor, lambda: not arm.device.busy, 2.0)
    assert took <= arm.accel_time_joint + 0.01
    assert run_until(executor, lambda: arm.state_word() == 0, 0.2) < 0.2   # the joints settled


def test_the_measurement_and_its_time_are_read_together(arm, executor):  # noqa: F811
    """~/state read the joints, then the clock: a step between the two stamped the pose one
    period late (1.2 mm at 300 mm/s against TF at that stamp)."""
    ready(arm)
    assert arm.move_ptp_joint_rel([10.0] * 7).ok
    for _ in range(30):
        executor.step()
        t, q = arm.measured()
        assert t == executor.world.time and q is arm.feedback_joints
        assert np.allclose(q, executor.world.arm_positions())


@pytest.mark.parametrize("time_step", [1.0 / 240.0, 0.01])
@pytest.mark.parametrize("setter", ["set_min_accel_time_joint", "set_min_accel_time_cartesian"])
def test_the_minimum_accel_time_is_at_least_two_control_cycles(setter, time_step):
    """Two cycles of the executor's period, whatever it is: exactly two is accepted, a hair
    less (and one and a half) is VALUE_ERR, and the accepted floor is the one kept."""
    from acti_motion.executor import MotionExecutor
    from acti_sim.world import World
    world = World(time_step=time_step)
    try:
        arm = ArmCore(MotionExecutor(world, real_time_factor=0.0))
        floor = 2 * time_step
        for below in (floor * (1 - 1e-9), 1.5 * time_step):
            r = getattr(arm, setter)(below)
            assert r.code == ReturnCode.VALUE_ERR and "two control cycles" in r.comment
        assert getattr(arm, setter)(floor).ok
        assert getattr(arm, setter.replace("set_", "get_"))().values["acl_time"] == floor
    finally:
        world.close()
