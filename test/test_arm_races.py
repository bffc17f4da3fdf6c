"""Spec races of pause, stop, servo_off and the offsets, without ROS: in the window between a
move's accept and its pick-up, between queued moves, while another thread plans and while a
stop decelerates. Every test records the commanded set-points (`trajectory_check`)."""
import threading

import numpy as np
import pytest

from acti_motion.arm.blending import blend_with_previous
from acti_motion.arm.core import ArmCore
from acti_motion.executor import MotionExecutor
from acti_motion.replies import ReturnCode as R
from acti_sim.world import World
from arm_fixtures import IDENTITY, arm, rest  # noqa: F401
from sim_fixtures import Announced, executor, run_until  # noqa: F401
from trajectory_check import ArmTrace

TOOL = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 100.0]
MOVING, PAUSED, SERVO = 0x02, 0x10, 0x01



@pytest.fixture
def trace(executor, arm):  # noqa: F811
    return ArmTrace(executor, arm)


def steps(executor, n):  # noqa: F811
    for _ in range(n):
        executor.step()


class HeldPlanner:
    """The real Cartesian planner, held at its start until released: lets a test act while
    another thread plans."""

    def __init__(self, arm) -> None:
        self.started, self.release = threading.Event(), threading.Event()
        plan = arm.planner.plan

        def held(*args, **kwargs):
            self.started.set()
            assert self.release.wait(30.0)
            return plan(*args, **kwargs)
        arm.planner.plan = held


def while_planning(arm, act):
    """Call act() while another thread plans a CP move (the real planner, held at its start);
    the reply of that move once act() returned and the planning went on."""
    held, out = HeldPlanner(arm), {}
    thread = threading.Thread(target=lambda: out.setdefault("reply", arm.move_linear_cartesian_rel(
        ([*IDENTITY[:3], 50.0, *IDENTITY[4:]], 0.0, 0))))
    thread.start()
    assert held.started.wait(30.0)
    act()
    held.release.set()
    thread.join(30.0)
    return out["reply"]


def while_b_waits_for_a(arm, act):
    """act() (true) while move B waits for the accept lock that move A holds while it plans;
    the replies of A and B."""
    out = {}

    def b_waits():
        announced = arm.device._accept = Announced(arm.device._accept)
        b = threading.Thread(target=lambda: out.setdefault(
            "b", arm.move_ptp_joint_rel([10.0] + [0.0] * 6)))
        b.start()
        assert announced.waits.wait(30.0)
        assert act()
        out["thread"] = b
    a = while_planning(arm, b_waits)
    out["thread"].join(30.0)
    return a, out["b"]


# --- pause ------------------------------------------------------------------------------------
def test_pause_right_after_accept_holds_the_move(arm, executor, trace):  # noqa: F811
    """Was: "ignored: the arm is not moving" while the state word said moving; the move ran on."""
    start = arm.device.hold.joints.copy()
    assert arm.move_ptp_joint_rel([10.0] * 7).ok
    assert arm.get_state().values["state"] & MOVING
    r = arm.pause()
    assert r.ok and not r.comment
    assert arm.get_state().values["state"] == SERVO | PAUSED
    steps(executor, 100)
    assert np.array_equal(trace.last, start) and arm.device.queue_length == 1
    assert arm.resume().ok
    rest(executor, arm)
    assert arm.device.completed == 1
    trace.check()
    trace.check_rest(start + np.radians(10.0))


def test_pause_between_two_queued_moves_holds_the_second(arm, executor, trace):  # noqa: F811
    assert arm.move_ptp_joint_rel([5.0] * 7).ok and arm.move_ptp_joint_rel([5.0] * 7).ok
    run_until(executor, lambda: arm.device.current is None and arm.device.queue_length == 1, 5.0)
    assert arm.get_state().values["state"] & MOVING
    assert arm.pause().ok and arm.device.paused
    first_end = arm.device.hold.joints.copy()
    steps(executor, 100)
    assert arm.device.current is None and arm.device.queue_length == 1
    trace.check_rest(first_end)
    assert arm.resume().ok
    rest(executor, arm)
    assert arm.device.completed == 2
    trace.check()


def test_pause_while_another_thread_plans_then_the_plan_waits(arm, executor, trace):  # noqa: F811
    assert arm.move_ptp_joint_rel([10.0] * 7).ok
    steps(executor, 50)

    def pause():
        assert arm.pause().ok and arm.device.paused          # not held up by the planning
    assert while_planning(arm, pause).ok
    run_until(executor, lambda: not arm.get_state().values["state"] & MOVING, 2.0)
    steps(executor, 100)
    assert arm.device.queue_length == 1 and arm.device.completed == 0   # both held
    assert arm.resume().ok
    rest(executor, arm)
    assert arm.device.completed == 2
    trace.check()


def test_pause_is_ignored_when_nothing_runs_or_is_queued(arm):
    r = arm.pause()
    assert r.ok and r.comment == "ignored: the arm is not moving" and not arm.device.paused


# --- stop ---------------------------------------------------------------------------------------
def test_a_move_sent_while_stop_decelerates_is_discarded(arm, executor, trace):  # noqa: F811
    """Was: kept, and run once the arm was at rest (5.4.19 discards every accumulated command)."""
    assert arm.move_ptp_joint_rel([20.0] * 7).ok
    steps(executor, 100)
    assert arm.stop().ok
    rest_at = arm.device.queued_end.joints.copy()
    steps(executor, 5)
    r = arm.move_ptp_joint_rel([5.0] * 7)
    assert r.ok and r.comment.startswith("discarded: stop")       # OK, and said
    late = r.values["motion_id"]
    rest(executor, arm)
    assert arm.device.was_discarded(late) and arm.device.completed == 0
    trace.check()
    trace.check_rest(rest_at)
    r = arm.move_ptp_joint_rel([1.0] * 7)
    assert r.ok and not r.comment                                 # at rest: runs again
    rest(executor, arm)
    assert arm.device.completed == 1
    trace.check()


def test_stop_while_another_thread_plans_discards_that_move(arm, executor, trace):  # noqa: F811
    assert arm.move_ptp_joint_rel([20.0] * 7).ok
    steps(executor, 100)
    rests = []

    def stop():
        assert arm.stop().ok                                     # not held up by the planning
        rests.append(arm.device.queued_end.joints.copy())
    r = while_planning(arm, stop)
    assert r.ok
    rest_at = rests[0]
    rest(executor, arm)
    assert arm.device.was_discarded(r.values["motion_id"]) and arm.device.completed == 0
    trace.check()
    trace.check_rest(rest_at)


def test_a_move_waiting_for_another_plan_is_refused_after_servo_off(arm, executor):  # noqa: F811
    """B passed the servo check, then waited while A planned; servo_off came meanwhile (the arm
    idle): B was queued after that stop and ran with the servo off."""
    start = arm.device.hold.joints.copy()
    a, b = while_b_waits_for_a(arm, lambda: arm.servo_off().ok)
    assert a.ok and arm.device.was_discarded(a.values["motion_id"])
    assert b.code == R.NOT_SV_ON_ERR, b
    steps(executor, 250)
    assert not arm.device.busy and np.allclose(arm.device.hold.joints, start)


def test_stop_between_accept_and_pick_up_moves_nothing(arm, executor, trace):  # noqa: F811
    start = arm.device.hold.joints.copy()
    assert arm.move_ptp_joint_rel([10.0] * 7).ok and arm.move_ptp_joint_rel([10.0] * 7).ok
    assert arm.stop().ok
    steps(executor, 50)
    assert not arm.device.busy and arm.device.discarded == 2
    trace.check_rest(start)


@pytest.mark.parametrize("paused_for", [0.0, 0.1, 0.5])
def test_a_faster_stop_while_a_stop_while_paused_decelerates_keeps_the_path(
        arm, executor, trace, paused_for):  # noqa: F811
    """Was: the rest point of the first stop was kept with the second's faster ramp: the
    set-point jumped ~1.9° at rest. The faster stop is the soft-limit watch's (fastest)."""
    assert arm.move_ptp_joint_rel([20.0] * 7).ok
    steps(executor, 100)
    assert arm.pause().ok
    run_until(executor, lambda: executor.world.time > 0.4 + paused_for, 2.0)
    assert arm.stop().ok
    steps(executor, 10)
    arm.stop_motion(fastest=True)
    rest_at = arm.device.queued_end.joints.copy()
    rest(executor, arm)
    trace.check()
    trace.check_rest(rest_at)


def test_pause_resume_and_stop_keep_every_set_point_continuous(arm, executor, trace):  # noqa: F811
    assert arm.move_ptp_joint_rel([20.0, -10.0, 15.0, 10.0, 15.0, 10.0, 20.0]).ok
    assert arm.move_linear_cartesian_rel(([*IDENTITY[:3], 60.0, *IDENTITY[4:]], 0.0, 0)).ok
    for op, after in (("pause", 0.15), ("resume", 0.1), ("pause", 0.5), ("resume", 0.6),
                      ("pause", 0.05), ("stop", 0.0)):
        assert getattr(arm, op)().ok
        run_until(executor, lambda t=executor.world.time + after: executor.world.time >= t, 2.0)
    rest_at = arm.device.queued_end.joints.copy()
    rest(executor, arm)
    trace.check()
    trace.check_rest(rest_at)


# --- servo_off, offsets, cycle --------------------------------------------------------------------
def test_servo_off_keeps_bit_0x01_until_the_arm_is_at_rest(arm, executor, trace):  # noqa: F811
    """Was: the bit was cleared ~0.3 s before the arm was at rest."""
    assert arm.move_ptp_joint_rel([20.0] * 7).ok
    steps(executor, 100)
    assert arm.servo_off().ok
    assert arm.move_ptp_joint_rel([1.0] * 7).code == R.NOT_SV_ON_ERR    # refused at once
    words = []
    run_until(executor, lambda: words.append(arm.state_word()) or words[-1] == 0, 2.0)
    assert all(w & SERVO for w in words[:-1]) and words[-1] == 0 and not arm.device.busy
    trace.check()


def test_control_point_offset_is_refused_while_paused_mid_move(arm, executor, trace):  # noqa: F811
    """Was: accepted, and the accepted target was then missed by the offset (100 mm)."""
    assert arm.move_linear_cartesian_rel(([*IDENTITY[:3], 60.0, *IDENTITY[4:]], 0.0, 0)).ok
    steps(executor, 60)
    assert arm.pause().ok
    run_until(executor, lambda: not arm.state_word() & MOVING, 2.0)
    r = arm.set_control_point_offset(TOOL)
    assert r.code == R.STATUS_ERR and "paused" in r.comment
    assert arm.move_ptp_joint_rel([1.0] * 7).ok
    assert arm.stop().ok
    rest(executor, arm)
    assert arm.set_control_point_offset(TOOL).ok
    trace.check()


@pytest.mark.parametrize("rate_hz, comment, cycle_ms", [(250.0, "", 4), (240.0, "4.1667 ms", 4),
                                                      (2000.0, "0.5000 ms", 1)])
def test_cmd_cycle_is_the_control_period(rate_hz, comment, cycle_ms):
    """ManipInfo.cmdCycle (common port) is the period of the position command in whole ms: at
    2 kHz (rate_hz's top) 0.5 ms was rounded to 0, a command cycle of none; it is 1, said."""
    world = World(time_step=1.0 / rate_hz)
    try:
        arm = ArmCore(MotionExecutor(world, 0.0))
        r = arm.get_manip_info()
        assert r.values["manip_info"][3] == cycle_ms
        assert (comment in r.comment) and (bool(r.comment) == bool(comment))
    finally:
        world.close()


@pytest.mark.parametrize("before_seam", [0.2, 0.1, 0.05, 0.0])
def test_pause_near_a_blend_seam_decelerates_along_the_next_move(arm, executor, trace,
                                                                  before_seam):  # noqa: F811
    """Was: a move cut to blend into the next (STROLIC SACC) ended at speed while a pause
    decelerated, and the set-point halted at the seam (up to 7× the acceleration limit)."""
    a = arm.move_ptp_joint_rel([20.0] * 7).values["motion_id"]
    b = arm.move_ptp_joint_rel([0.0, 20.0, 0.0, 0.0, 0.0, 0.0, 0.0]).values["motion_id"]
    assert blend_with_previous(arm.device, b, a, 0.05, lambda q: arm.tool_pose(q)[:3, 3]) > 0.1
    seam = arm.device.queue[0].motion.duration
    run_until(executor, lambda: executor.world.time >= seam - before_seam, 5.0)
    assert arm.pause().ok
    run_until(executor, lambda: not arm.state_word() & MOVING, 2.0)
    assert arm.resume().ok
    rest(executor, arm)
    assert arm.device.completed == 2
    trace.check()


class FailsAfter:
    """Fault injection: a real planned arm motion whose set-points fail past `t_fail` (a bug
    that no check foresaw)."""

    def __init__(self, motion, t_fail: float) -> None:
        self.motion, self.t_fail = motion, t_fail
        self.duration, self.ramp, self.kind = motion.duration, motion.ramp, motion.kind

    def at(self, t):
        return self.motion.at(t)

    def apply(self, world, t, rate):
        if t > self.t_fail:
            raise FloatingPointError("set-point is NaN")
        self.motion.apply(world, t, rate)


def test_a_motion_that_fails_while_running_is_discarded_and_the_simulation_goes_on(
        arm, executor, trace, caplog):  # noqa: F811
    """Was: an exception in a running motion ended the simulation thread (the whole main job)."""
    assert arm.move_ptp_joint_rel([10.0] * 7).ok
    planned = arm.device.queue.pop().motion
    broken = arm.device.submit(lambda start: FailsAfter(planned, 0.2), "broken")
    assert arm.move_ptp_joint_rel([5.0] * 7).ok
    run_until(executor, lambda: not arm.device.busy, 2.0)                 # steps on, no raise
    assert arm.device.was_discarded(broken) and arm.device.discarded == 2
    assert "FloatingPointError: set-point is NaN" in caplog.text
    assert arm.move_ptp_joint_rel([-5.0] * 7).ok                          # and moves again
    rest(executor, arm)
    assert arm.device.completed == 1


@pytest.mark.parametrize("first", ["servo_off", "stop"])
def test_a_stop_between_pauses_check_and_its_act_leaves_nothing_paused(arm, executor, first):  # noqa: F811
    """pause checked (a move queued, servo on), then servo_off or stop discarded the queue, then
    pause paused the idle arm: later moves were accepted and never ran."""
    assert arm.move_ptp_joint_rel([10.0] * 7).ok               # queued, not picked up yet
    checked, go, out = threading.Event(), threading.Event(), {}
    pause = arm.device.pause

    def held(*args, **kwargs):
        checked.set()
        assert go.wait(30.0)
        return pause(*args, **kwargs)
    arm.device.pause = held
    p = threading.Thread(target=lambda: out.setdefault("pause", arm.pause()))
    p.start()
    assert checked.wait(30.0)
    assert getattr(arm, first)().ok
    go.set()
    p.join(30.0)
    assert out["pause"].ok and "ignored" in out["pause"].comment
    assert not arm.device.paused and not arm.state_word() & 0x10
    assert arm.servo_on().ok
    motion = arm.move_ptp_joint_rel([5.0] + [0.0] * 6).values["motion_id"]
    run_until(executor, lambda: arm.device.is_over(motion), 5.0)
    assert not arm.device.was_discarded(motion)


def test_offsets_are_refused_while_a_move_is_planned(arm, executor):  # noqa: F811
    """A move copied the frames when called and planned with them while an offset set
    meanwhile was answered OK: it ended 20 mm from where the new frame put its target."""
    before = arm.get_feedback_pos_cartesian().values["pos"][0][3]
    shifted = [*IDENTITY[:3], 20.0, *IDENTITY[4:]]
    answers = {}

    def set_offsets():
        answers["base"] = arm.set_base_offset(shifted)
        answers["tool"] = arm.set_control_point_offset(shifted)
    assert while_planning(arm, set_offsets).ok                 # the move: +50 mm in x
    assert answers["base"].code == R.NG and "planned" in answers["base"].comment
    assert answers["tool"].code == R.STATUS_ERR and "planned" in answers["tool"].comment
    run_until(executor, lambda: not arm.device.busy, 10.0)
    after = arm.get_feedback_pos_cartesian().values["pos"][0][3]
    assert after - before == pytest.approx(50.0, abs=0.05)


def test_a_blend_is_watched_strictly_only_on_the_limits_that_changed_between_its_moves(arm):
    """A blend of moves checked under different limits (one changed while paused) was watched
    as if every limit had changed: a move back inside on any other row could be alarmed."""
    a = arm.move_ptp_joint_rel([20.0] * 7).values["motion_id"]
    b = arm.move_ptp_joint_rel([0.0, 20.0, 0.0, 0.0, 0.0, 0.0, 0.0]).values["motion_id"]
    first, second = arm.device.queue[0].motion, arm.device.queue[1].motion
    second.limits_checked = first.limits_checked.copy()
    second.limits_checked[3, 1] -= 10.0                       # J4's upper limit changed
    assert blend_with_previous(arm.device, b, a, 0.05, lambda q: arm.tool_pose(q)[:3, 3]) > 0.1
    merged = arm.device.queue[1].motion.limits_checked
    assert np.isnan(merged[3, 1]) and np.isnan(merged).sum() == 1
    assert np.array_equal(np.delete(merged.ravel(), 7), np.delete(first.limits_checked.ravel(), 7))


def test_a_move_planned_across_the_end_of_a_stop_is_discarded(arm, executor, trace):  # noqa: F811
    """Sent while the stop decelerated, planned until after the arm was at rest: it was queued
    then and ran (5.4.19 discards every command given until the arm is at rest)."""
    assert arm.move_ptp_joint_rel([20.0] * 7).ok
    steps(executor, 100)
    assert arm.stop().ok and arm.device.stopping
    rest_at = arm.device.queued_end.joints.copy()

    def at_rest():
        run_until(executor, lambda: not arm.device.busy, 5.0)
    r = while_planning(arm, at_rest)
    assert r.ok and r.comment.startswith("discarded: stop"), r
    steps(executor, 250)
    assert arm.device.was_discarded(r.values["motion_id"]) and arm.device.completed == 0
    trace.check_rest(rest_at)


def test_a_move_sent_before_a_stop_and_planned_after_it_is_discarded(arm, executor):  # noqa: F811
    """B waited for A's plan; a stop came (the arm idle, so at rest at once); B was then
    planned under the stop's new generation, queued and ran: a command given before the stop."""
    start = arm.device.hold.joints.copy()
    a, b = while_b_waits_for_a(arm, lambda: arm.stop().ok)
    assert a.ok and arm.device.was_discarded(a.values["motion_id"])
    assert b.ok and arm.device.was_discarded(b.values["motion_id"]), b
    steps(executor, 250)
    assert not arm.device.busy and np.allclose(arm.device.hold.joints, start)


# --- the state word: one moment's ------------------------------------------------------------------
@pytest.mark.parametrize("halt", ["stop", "servo_off"])
def test_a_paused_arm_at_rest_is_not_moving_right_after_stop_or_servo_off(arm, executor, halt):  # noqa: F811
    """Was 0x03 until the next control period: the stop cleared the pause, and the word, read
    in parts, saw a current motion without the pause that held it at rest."""
    assert arm.move_ptp_joint_rel([20.0] * 7).ok
    steps(executor, 60)
    assert arm.pause().ok
    run_until(executor, lambda: arm.state_word() == SERVO | PAUSED, 2.0)
    assert getattr(arm, halt)().ok
    word = arm.state_word()                           # before the simulation steps again
    assert not word & MOVING and word == (SERVO if halt == "stop" else 0)
    steps(executor, 3)
    assert arm.state_word() == (SERVO if halt == "stop" else 0) and not arm.device.busy


@pytest.mark.parametrize("halt", ["stop", "servo_off"])
def test_a_move_sent_right_after_a_halt_at_rest_runs(arm, executor, trace, halt):  # noqa: F811
    """A paused arm at rest has nothing to decelerate, so its stop is over at once: a move
    accepted before the next control step was discarded as if it had come during a
    deceleration ("discarded: stop", over DDS at load 10)."""
    assert arm.move_ptp_joint_rel([20.0] * 7).ok
    steps(executor, 60)
    assert arm.pause().ok
    run_until(executor, lambda: arm.state_word() == SERVO | PAUSED, 2.0)
    assert getattr(arm, halt)().ok
    arm.servo_on()
    r = arm.move_ptp_joint_rel([4.0] * 7)          # before the simulation steps again
    assert r.ok and not r.comment                  # not "discarded: stop"
    moved = r.values["motion_id"]
    rest(executor, arm)
    assert arm.device.completed == 1 and not arm.device.was_discarded(moved)
    trace.check()


def test_the_moving_bit_lasts_while_the_measured_joints_move(arm, executor):  # noqa: F811
    """After a stop the set-point rests, and the joints follow it for a few control periods
    more: the word said not moving (and, after servo_off, 0x00) while they still moved."""
    from acti_motion.arm.watch import SETTLED_DEG_S
    assert arm.move_ptp_joint_rel([30.0] * 7).ok
    steps(executor, 80)
    assert arm.stop().ok
    tail = []                     # (device busy, measured speed °/s, word) each period after
    for _ in range(200):
        executor.step()
        speed = float(np.degrees(np.abs(executor.world.arm_velocities())).max())
        tail.append((arm.device.busy, speed, arm.state_word()))
        if not tail[-1][2] & MOVING:
            break
    assert all(word & MOVING for busy, speed, word in tail if busy or speed > SETTLED_DEG_S)
    settling = [speed for busy, speed, word in tail if not busy and word & MOVING]
    assert settling and settling[0] > SETTLED_DEG_S      # the tail this covers exists
    assert tail[-1][2] == SERVO and tail[-1][1] <= SETTLED_DEG_S
