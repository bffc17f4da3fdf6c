"""VehicleCore motions in the real simulation, without ROS: straight, turn, circular moves end on
target (odometry, and the ground truth agrees), the queue, pause/resume/stop."""
import math

import pytest

from acti_motion.arm.core import ArmConfig, ArmCore
from acti_motion.vehicle.paths import TrackedBaseMotion
from acti_motion.vehicle.core import VehicleState
from sim_fixtures import executor, run_until  # noqa: F401
from vehicle_fixtures import assert_at, base, position, ready, settle, state, steps, trace  # noqa: F401


TRACKING_SETTLE = TrackedBaseMotion.SETTLE


def truth_mm(executor):  # noqa: F811
    x, y, th = executor.world.base_pose()
    return 1000.0 * x, 1000.0 * y, math.degrees(th)


@pytest.mark.parametrize("distance", [500.0, -300.0])
def test_move_forward_ends_within_5_mm(base, executor, distance):  # noqa: F811
    ready(base)
    x0 = truth_mm(executor)[0]
    assert base.move_forward(distance).ok
    assert state(base) == VehicleState.BUSY
    settle(executor, base)
    assert_at(base, distance, 0.0, 0.0)
    assert state(base) == VehicleState.READY
    # wheel odometry agrees with the ground truth (true cylinders, sprung casters)
    assert abs(truth_mm(executor)[0] - x0 - distance) < 2.0


@pytest.mark.parametrize("angle", [90.0, -135.0, 400.0])
def test_move_turn_counter_clockwise_positive(base, executor, angle):  # noqa: F811
    ready(base)
    assert base.move_turn(angle).ok
    settle(executor, base)
    assert_at(base, 0.0, 0.0, angle)
    assert abs(math.remainder(truth_mm(executor)[2] - angle, 360.0)) < 0.5


def test_move_linear_rel_then_abs_queue_and_stop_at_each(base, executor):  # noqa: F811
    ready(base)
    assert base.move_linear_rel((300.0, 400.0, -30.0)).ok
    assert base.move_linear_abs((0.0, 600.0, 180.0)).ok          # servo-on: queues while Busy
    rest = base.device.queue[1].motion
    settle(executor, base)
    assert_at(base, 0.0, 600.0, 180.0)
    assert rest.path.twist(0.0) == (0.0, 0.0)                     # starts from rest
    tx, ty, _ = truth_mm(executor)
    assert math.hypot(tx, ty - 600.0) < 15.0


def test_move_linear_rel_behind_goes_backwards(base, executor):  # noqa: F811
    ready(base)
    assert base.move_linear_rel((-400.0, 0.0, 0.0)).ok
    settle(executor, base)
    assert_at(base, -400.0, 0.0, 0.0)
    assert base.device.completed == 1


@pytest.mark.parametrize("centre_y, angle, end", [
    (500.0, 90.0, (500.0, 500.0, 90.0)),
    (-400.0, -90.0, (400.0, -400.0, -90.0)),
    (300.0, -60.0, (-300.0 * math.sin(math.radians(60)), 300.0 - 300.0 * math.cos(math.radians(60)), -60.0)),
])
def test_move_circular_rel_about_a_point_on_the_axle(base, executor, centre_y, angle, end):  # noqa: F811
    ready(base)
    assert base.move_circular_rel((0.0, centre_y), angle).ok
    speeds = []
    run_until(executor, lambda: speeds.append(base.odometry.v) or not base.device.busy, 20.0)
    assert_at(base, *end)
    assert max(abs(v) for v in speeds) <= base.velocity[0] / 1000.0 * 1.05


def test_circular_rel_about_the_centre_of_the_axle_turns_in_place(base, executor):  # noqa: F811
    ready(base)
    assert base.move_circular_rel((0.0, 0.0), -45.0).ok
    settle(executor, base)
    assert_at(base, 0.0, 0.0, -45.0)


def test_circular_rel_off_the_axle_is_refused(base):
    ready(base)
    r = base.move_circular_rel((100.0, 500.0), 90.0)
    assert not r.ok and "x = 0" in r.comment and base.device.last_id == 0


def test_moves_respect_the_velocity_setting(base, executor):  # noqa: F811
    ready(base)
    base.set_velocity((200.0, 30.0))
    base.move_forward(800.0)
    speeds = []
    took = run_until(executor, lambda: speeds.append(base.odometry.v) or not base.device.busy, 20.0)
    assert max(speeds) < 0.21 and took > 4.0


def test_full_queue_refuses_and_keeps_what_is_queued(base):
    ready(base)
    for _ in range(4):
        assert base.move_linear_abs((100.0, 0.0, 0.0)).ok
    r = base.move_linear_abs((200.0, 0.0, 0.0))
    assert not r.ok and "full" in r.comment
    assert base.device.queue_length == 4


def test_pause_keeps_the_queue_and_accepts_new_motions_resume_runs_them(base, executor, trace):  # noqa: F811
    ready(base)
    base.move_forward(600.0)
    trace.step(1.0)
    assert base.pause().ok and state(base) == VehicleState.BUSY        # decelerating
    trace.step(1.0)
    assert state(base) == VehicleState.PAUSED
    held = position(base)
    trace.step(1.0)
    assert position(base) == pytest.approx(held, abs=0.5)          # at rest
    assert abs(base.odometry.v) < 1e-3
    assert base.move_turn(90.0).ok                                  # Paused accepts "Ready only"
    assert base.move_linear_abs((600.0, 300.0, 90.0)).ok
    assert base.device.queue_length == 2 and state(base) == VehicleState.PAUSED
    assert base.resume().ok
    trace.until_idle()
    trace.check()
    assert_at(base, 600.0, 300.0, 90.0)
    assert base.device.completed == 3


def test_while_paused_a_continuous_move_queues_for_resume_and_a_jog_discards_nothing(
        base, executor, trace):  # noqa: F811
    """pause: 動作指令は廃棄されません; 一時停止状態で入力された動作指令は…resume()実行後に実行.
    A jog or a continuous move took over the paused move: it was lost, and the base stood."""
    ready(base)
    first = base.move_forward(600.0).values["motion_id"]
    trace.step(1.0)
    assert base.pause().ok
    trace.until(lambda: state(base) == VehicleState.PAUSED, 3.0)
    r = base.move_jog(100.0, 0.0, 0.0)
    assert not r.ok and "Paused" in r.comment
    r = base.move_continuous_rel((0.0, 0.0, 90.0))
    assert r.ok and r.values["motion_id"] == first + 1 and base.device.queue_length == 1
    assert base.resume().ok
    trace.until_idle()
    trace.check()
    assert_at(base, 600.0, 0.0, 90.0)
    assert (base.device.completed, base.device.discarded) == (2, 0)


def test_a_base_at_rest_holds_its_pose(base, executor):  # noqa: F811
    """With the arm held on it, as in the main job: the wheels' velocity motors at 0 let the
    base creep (its heading 0.34° in 2 min, odometry along); at rest the wheels are held."""
    assert ArmCore(executor, ArmConfig()).servo_on().ok
    ready(base)
    steps(executor, 1.0)
    x0, y0, yaw0 = executor.world.base_pose()
    odometry0 = position(base)
    steps(executor, 60.0)
    x1, y1, yaw1 = executor.world.base_pose()
    assert math.dist((x0, y0), (x1, y1)) < 2e-4 and abs(math.degrees(yaw1 - yaw0)) < 0.01
    assert position(base) == pytest.approx(odometry0, abs=0.2)


def test_stop_decelerates_at_the_maximum_and_discards_everything(base, executor, trace):  # noqa: F811
    ready(base)
    base.set_velocity((600.0, 45.0))
    base.move_forward(3000.0)
    base.move_turn(90.0)
    trace.until(lambda: base.odometry.v > 0.59, 5.0)
    assert base.stop().ok
    rest = base.device.queued_end
    assert base.device.queue_length == 0
    took = trace.until_idle()
    trace.check(rest=rest)
    assert took < 0.6 / 1.0 + TRACKING_SETTLE + 0.1
    assert state(base) == VehicleState.READY
    x, y, th = position(base)
    assert x < 3000.0 and abs(th) < 0.5
    assert base.move_forward(100.0).ok                              # and it moves on


def test_servo_off_while_moving_stops_first(base, executor, trace):  # noqa: F811
    ready(base)
    base.move_forward(1000.0)
    trace.step(1.0)
    assert base.set_servo(False).ok and state(base) == VehicleState.POWERED
    rest = base.device.queued_end
    trace.until_idle(2.0)
    trace.check(rest=rest)
    steps(executor, 0.5)
    assert abs(base.odometry.v) < 1e-3


def speeds_until_done(executor, base, seconds=30.0):  # noqa: F811
    speeds = []
    run_until(executor, lambda: speeds.append(base.odometry.v) or not base.device.busy, seconds)
    return speeds


@pytest.mark.parametrize("before, after", [(300.0, 600.0), (600.0, 200.0)])
def test_set_velocity_while_moving_changes_speed_smoothly(base, executor, before, after):  # noqa: F811
    ready(base)
    base.set_velocity((before, 45.0))
    base.move_forward(3000.0)
    assert base.move_linear_abs((1500.0, 0.0, 0.0)).ok              # queued: takes it too
    steps(executor, 2.0)
    assert base.odometry.v == pytest.approx(before / 1000.0, abs=0.01)
    assert base.set_velocity((after, 45.0)).ok
    speeds = speeds_until_done(executor, base)
    assert speeds[int(2.0 / executor.dt)] == pytest.approx(after / 1000.0, abs=0.01)
    accel = max(abs(b - a) for a, b in zip(speeds, speeds[1:])) / executor.dt
    assert accel < 0.5 * 1.3                                       # the acceleration setting
    assert min(speeds) == pytest.approx(-after / 1000.0, abs=0.01)  # the queued move
    assert_at(base, 1500.0, 0.0, 0.0)


def test_set_velocity_while_turning(base, executor):  # noqa: F811
    ready(base)
    base.move_turn(180.0)
    steps(executor, 1.5)
    assert math.degrees(base.odometry.w) == pytest.approx(45.0, abs=1.0)
    base.set_velocity((300.0, 20.0))
    steps(executor, 1.0)
    assert math.degrees(base.odometry.w) == pytest.approx(20.0, abs=1.0)
    settle(executor, base)
    assert_at(base, 0.0, 0.0, 180.0)


def test_the_fastest_arm_move_does_not_push_the_standing_base(base, executor):  # noqa: F811
    """At 100 % and the shortest accel time, a reach forward and back pushed the 40 kg base
    21 mm and turned it 5° on the floor (more in a day's work), where no wheel turned, so
    odometry never saw it. The base now weighs what a mobile manipulator's does (80 kg)."""
    home = (0.0, 30.0, 0.0, -60.0, 0.0, 60.0, 0.0)
    arm = ArmCore(executor, ArmConfig(queue_size=8, initial_joints_deg=home))
    ready(base)
    assert arm.servo_on().ok and arm.set_speed_joint(100).ok and arm.set_accel_time_joint(0.1).ok
    x0, y0, th0 = executor.world.base_pose()
    for _ in range(2):
        for target in ([33.0, 52.6, -14.3, -43.0, 0.0, 60.0, -15.5], list(home)):
            assert arm.move_ptp_joint_abs(target).ok
            run_until(executor, lambda: not arm.device.busy, 10.0)
    steps(executor, 0.2)
    x1, y1, th1 = executor.world.base_pose()
    assert math.hypot(x1 - x0, y1 - y0) < 0.004 and abs(math.degrees(th1 - th0)) < 0.1
    assert state(base) == VehicleState.READY
