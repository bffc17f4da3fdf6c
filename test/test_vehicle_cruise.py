"""move_cruise_abs without ROS: a smooth path through every point, timed by TOPP-RA, that never
stops between the points and ends on the last."""
import math

import pytest

from sim_fixtures import executor  # noqa: F401
from vehicle_fixtures import assert_at, base, ready, steps, trace  # noqa: F401

POINTS = [(1000.0, 500.0), (2000.0, 0.0), (3000.0, 500.0), (3300.0, 1300.0)]


def record(executor, base, add_later=()):  # noqa: F811
    """Run until the base is done, adding points (time s, point) on the way; the trace
    (x mm, y mm, forward speed m/s, yaw rate rad/s) at every step."""
    trace, pending = [], list(add_later)
    while base.device.busy or pending:
        if pending and executor.world.time >= pending[0][0]:
            assert base.move_cruise_abs(pending.pop(0)[1]).values["motion_id"] == 1
        executor.step()
        p = base.odometry.pose
        trace.append((1000.0 * p.x, 1000.0 * p.y, base.odometry.v, base.odometry.w))
        assert executor.world.time < 60.0
    return trace


def check_passes_every_point_without_stopping(trace, points):
    passes = [min(range(len(trace)), key=lambda i: math.dist(trace[i][:2], p)) for p in points]
    for p, i in zip(points, passes):
        assert math.dist(trace[i][:2], p) < 10.0, p            # passed (odometry within 10 mm)
    assert passes == sorted(passes)                            # in order
    near_end = next(i for i in range(passes[0], len(trace)) if math.dist(trace[i][:2], points[-1]) < 100.0)
    assert min(s[2] for s in trace[passes[0]:near_end]) > 0.05  # never stops between the points


def test_cruise_through_queued_points(base, executor):  # noqa: F811
    ready(base)
    for p in POINTS:
        assert base.move_cruise_abs(p).values["motion_id"] == 1   # one motion, extended
    trace = record(executor, base)
    check_passes_every_point_without_stopping(trace, POINTS)
    assert_at(base, *POINTS[-1], theta=base.get_position().values["pos"][2])
    assert base.device.completed == 1


def test_points_added_while_cruising_are_passed_smoothly(base, executor):  # noqa: F811
    ready(base)
    base.move_cruise_abs(POINTS[0])
    trace = record(executor, base, [(1.0 + i, p) for i, p in enumerate(POINTS[1:])])
    check_passes_every_point_without_stopping(trace, POINTS)
    x, y, _ = base.get_position().values["pos"]
    assert math.dist((x, y), POINTS[-1]) < 5.0


def test_cruise_respects_the_velocity_and_acceleration_settings(base, executor):  # noqa: F811
    ready(base)
    base.set_velocity((400.0, 30.0))
    base.set_acceleration((300.0, 60.0))
    for p in POINTS[:3]:
        base.move_cruise_abs(p)
    motion = base.device.queue[0].motion
    path = motion.path
    dt = 0.005
    vs = [path.twist(i * dt) for i in range(int(path.duration / dt))]
    assert max(v for v, _ in vs) <= 0.4 + 1e-6
    assert max(abs(w) for _, w in vs) <= math.radians(30.0) * 1.01
    accel = max(abs(b[0] - a[0]) / dt for a, b in zip(vs, vs[1:]))
    assert accel <= 0.3 * 1.05
    trace = record(executor, base)
    assert max(s[2] for s in trace) < 0.4 * 1.05


def test_cruise_to_a_point_behind_turns_first_and_queues_after_other_moves(base, executor):  # noqa: F811
    ready(base)
    assert base.move_linear_abs((500.0, 0.0, 0.0)).ok
    assert base.move_cruise_abs((0.0, 300.0)).values["motion_id"] == 2
    record(executor, base)
    x, y, _ = base.get_position().values["pos"]
    assert math.dist((x, y), (0.0, 300.0)) < 5.0


@pytest.mark.parametrize("added_while", ["queued", "cruising"])
def test_a_point_that_reverses_the_path_stops_there_and_goes_back(base, executor, added_while):  # noqa: F811
    """A point straight back along the path is a cusp no differential drive passes: the base
    stops at the point before, turns and goes on (it went Stuck, the cruise not completed)."""
    ready(base)
    assert base.move_cruise_abs((1000.0, 0.0)).ok
    if added_while == "cruising":
        steps(executor, 2.0)
    assert base.move_cruise_abs((0.0, 0.0)).ok
    trace = record(executor, base)
    assert not base.stuck and not base.alarms.active()
    assert math.dist(trace[-1][:2], (0.0, 0.0)) < 5.0
    assert max(x for x, *_ in trace) == pytest.approx(1000.0, abs=10.0)
    assert (base.device.completed, base.device.discarded) == (2, 0)


@pytest.mark.parametrize("point", [(math.nan, 0.0), (0.0, math.inf)])
def test_cruise_refuses_bad_points(base, point):
    ready(base)
    r = base.move_cruise_abs(point)
    assert not r.ok and "finite" in r.comment and base.device.last_id == 0


def test_cruise_needs_the_servo(base):
    r = base.move_cruise_abs((100.0, 0.0))
    assert not r.ok and "Unpowered" in r.comment


# --- move_continuous_rel -------------------------------------------------------------------
def run_recording_speed(executor, base, seconds=None):  # noqa: F811
    speeds = []
    limit = executor.world.time + (seconds if seconds is not None else 60.0)
    while (base.device.busy if seconds is None else True) and executor.world.time < limit:
        executor.step()
        speeds.append(base.odometry.v)
    return speeds


def reference_now(base):
    return base.device.current.motion.at(base.device.t)


def expected_mm(pose, rel):
    from acti_motion.vehicle.paths import Pose2D
    g = pose.compose(Pose2D(rel[0] / 1000.0, rel[1] / 1000.0, math.radians(rel[2])))
    return 1000.0 * g.x, 1000.0 * g.y, math.degrees(g.theta)


def max_accel(speeds, dt):
    return max(abs(b - a) for a, b in zip(speeds, speeds[1:])) / dt


def test_continuous_rel_from_rest(base, executor):  # noqa: F811
    ready(base)
    assert base.move_continuous_rel((300.0, 400.0, 45.0)).ok
    run_recording_speed(executor, base)
    assert_at(base, 300.0, 400.0, 45.0)


def setting(base):
    (at, ar) = base.acceleration
    return at / 1000.0, math.radians(ar)


@pytest.mark.parametrize("rel, keeps_moving", [((1500.0, 400.0, 30.0), True),
                                                ((-500.0, 0.0, 0.0), False)])
def test_continuous_rel_new_target_replaces_the_old_with_continuous_velocity(
        base, executor, trace, rel, keeps_moving):  # noqa: F811
    ready(base)
    first = base.move_continuous_rel((2000.0, 0.0, 0.0)).values["motion_id"]
    trace.step(1.5)
    here = reference_now(base)
    # the old target is erased (連続実行…最後に設定された目標点以外は消去): its id is over, not
    # completed, and the motion runs on as the new command's
    assert base.move_continuous_rel(rel).values["motion_id"] == first + 1
    assert base.device.is_over(first) and base.device.was_discarded(first)
    trace.until_idle()
    assert_at(base, *expected_mm(here, rel))
    trace.check(accel=setting(base))                              # no jump in speed
    transition = [p.v for p in trace.points[int(1.5 / executor.dt):int(2.5 / executor.dt)]]
    assert (min(transition) > 0.2) == keeps_moving
    assert base.device.completed == 1


def turned_until_idle(executor, base):  # noqa: F811
    """Degrees the base turned (signed, summed step by step) until it has nothing left to do."""
    total, last = 0.0, base.odometry.pose.theta
    while base.device.busy:
        executor.step()
        total += math.remainder(base.odometry.pose.theta - last, 2 * math.pi)
        last = base.odometry.pose.theta
    return math.degrees(total)


@pytest.mark.parametrize("theta", [270.0, 360.0, -200.0])
def test_continuous_rel_turns_by_its_theta_also_when_it_takes_over(base, executor, theta):  # noqa: F811
    """1.4.15 pos.theta: the target heading relative to the base, turned as given (270°
    counter-clockwise), as from rest and as move_linear_rel. Taking over a moving base, the
    final turn was wrapped: 270° turned 90° clockwise, 360° not at all."""
    ready(base)
    assert base.move_continuous_rel((0.0, 0.0, theta)).ok
    assert turned_until_idle(executor, base) == pytest.approx(theta, abs=0.5)
    base.move_forward(3000.0)
    steps(executor, 1.5)
    assert base.move_continuous_rel((1500.0, 200.0, theta)).ok
    assert turned_until_idle(executor, base) == pytest.approx(theta, abs=0.5)

def test_continuous_rel_keeps_only_the_last_target(base, executor):  # noqa: F811
    ready(base)
    base.move_continuous_rel((1000.0, 0.0, 0.0))
    steps(executor, 0.5)
    for rel in [(800.0, 200.0, 0.0), (600.0, -100.0, 10.0), (700.0, 0.0, -20.0)]:
        here = reference_now(base)
        assert base.move_continuous_rel(rel).ok
        steps(executor, 0.02)
    run_recording_speed(executor, base)
    assert_at(base, *expected_mm(here, rel))


def test_continuous_rel_replaces_the_moves_not_started_yet(base, executor):  # noqa: F811
    ready(base)
    base.move_linear_abs((500.0, 0.0, 90.0))
    base.move_continuous_rel((100.0, 0.0, 0.0))
    assert base.move_continuous_rel((300.0, 0.0, 0.0)).values["motion_id"] == 3
    run_recording_speed(executor, base)
    assert_at(base, 300.0, 0.0, 0.0)
    assert (base.device.completed, base.device.discarded) == (1, 2)


@pytest.mark.parametrize("running", ["move_linear_abs", "move_cruise_abs"])
def test_continuous_rel_takes_over_another_kind_of_move_smoothly(base, executor, trace, running):  # noqa: F811
    ready(base)
    if running == "move_linear_abs":
        base.move_linear_abs((3000.0, 0.0, 0.0))
    else:
        base.move_cruise_abs((3000.0, 0.0))
    base.move_linear_abs((0.0, 0.0, 0.0))                       # queued behind: given up
    trace.step(2.0)
    here = reference_now(base)
    r = base.move_continuous_rel((800.0, 300.0, 0.0))
    assert r.ok and base.device.current.label == "move_continuous_rel"
    assert base.device.queue_length == 0
    trace.until_idle()
    assert_at(base, *expected_mm(here, (800.0, 300.0, 0.0)))
    trace.check(accel=setting(base))
    assert min(p.v for p in trace.points[int(2.0 / executor.dt):int(2.5 / executor.dt)]) > 0.2
    # the queued move and the one taken over (it never reached its goal) are discarded
    assert (base.device.completed, base.device.discarded) == (1, 2)


def test_set_velocity_while_cruising(base, executor):  # noqa: F811
    ready(base)
    base.set_velocity((600.0, 90.0))
    for p in POINTS:
        base.move_cruise_abs(p)
    trace = []
    for _ in range(int(3.0 / executor.dt)):
        executor.step()
        p = base.odometry.pose
        trace.append((1000.0 * p.x, 1000.0 * p.y, base.odometry.v, base.odometry.w))
    assert base.set_velocity((200.0, 90.0)).ok
    trace += record(executor, base)
    check_passes_every_point_without_stopping(trace, POINTS)
    later = [s[2] for s in trace[int(4.5 / executor.dt):-int(2.0 / executor.dt)]]
    assert max(later) < 0.21                                       # slowed to the new setting
    x, y, _ = base.get_position().values["pos"]
    assert math.dist((x, y), POINTS[-1]) < 5.0
