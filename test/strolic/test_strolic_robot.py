"""The robot-control functions ED00–ED23 on the simulated arm, without ROS: the case table
(strolic_robot_cases.py), then what the simulation shows: poses reached, blending through via
points without stopping, $WAIT and DELAY timing, PAUSE, motion errors and cancel as exceptions
that stop the arm."""
from __future__ import annotations


import numpy as np
import pytest

from acti_motion.arm.core import ArmConfig, ArmCore
from acti_motion.executor import MotionExecutor
from acti_motion.programs.robot import MAX_RAMP
from acti_motion.programs.run import (RESULT_CHARS, RESULT_ITEM, ProgramRun, Status, shown_output,
                                      shown_stack)
from acti_sim.world import World
from sim_fixtures import executor  # noqa: F401
from strolic.codes import I2, Num, Str
from strolic.errors import ExceptionKind as K
from strolic.literals import format_value
from strolic.text import assemble
from strolic.values import encode_value
from strolic_robot_cases import CASES, WORK, Check, numbers

MAX_SIM_SECONDS = 60.0


@pytest.fixture
def arm(executor):  # noqa: F811
    a = ArmCore(executor, ArmConfig(queue_size=8, initial_joints_deg=WORK))
    assert a.servo_on().ok
    return a


def run(arm, executor, text, *, servo=True, resume_after=None, hook=None, **options):  # noqa: F811
    """Run a program, stepping the simulation while it waits; `hook()` after every step."""
    if not servo:
        assert arm.servo_off().ok
    t0 = executor.world.time

    def step():
        executor.step()
        elapsed = executor.world.time - t0
        if elapsed > MAX_SIM_SECONDS:
            raise AssertionError(f"the program ran for more than {MAX_SIM_SECONDS} s")
        if resume_after is not None and elapsed >= resume_after and arm.device.paused:
            assert arm.resume().ok
        if hook is not None:
            hook()
    return ProgramRun(arm, text, step=step, **options).run()


CASE_ROWS = [pytest.param(case[0], case[1], case[2] if len(case) > 2 else {},
                          id=f"{mnemonic}-{i}")
             for mnemonic, cases in CASES.items() for i, case in enumerate(cases)]


@pytest.mark.parametrize("program, expected, options", CASE_ROWS)
def test_case(arm, executor, program, expected, options):  # noqa: F811
    result = run(arm, executor, program, **options)
    if isinstance(expected, K):
        assert result.status is Status.EXCEPTION, (result.stack, result.console)
        assert result.error.kind is expected, result.report
    else:
        assert result.status is Status.FINISHED, (result.report, result.console)
        if isinstance(expected, Check):
            assert expected(result.stack, arm), (expected.what, result.stack, result.console)
        else:
            assert result.stack == expected, result.console


# --- what the simulation shows -------------------------------------------------------------------
SQUARE = ("HERE Vec(0 150 0) DEV HERE Vec(0 150 -150) DEV HERE Vec(0 0 -150) DEV 3 #Pm(120) CONSA")
CORNERS = np.array([[0, 150, 0], [0, 150, -150], [0, 0, -150]], float)


def traced(arm, executor, text, **options):  # noqa: F811
    """Run and record the measured control point (mm) at every step: result, times, points."""
    log = []
    executor.after_step(lambda world: log.append(
        (world.time, arm.tool_pose(world.arm_positions())[:3, 3] * 1000.0)))
    result = run(arm, executor, text, **options)
    return result, np.array([t for t, _ in log]), np.array([p for _, p in log])


def speeds(times, points):
    return np.linalg.norm(np.diff(points, axis=0), axis=1) / np.diff(times)


@pytest.mark.parametrize("move", ["ALMOVE", "AJMOVE"])
def test_pose_sequence_stops_at_each_pose_without_sacc(arm, executor, move):  # noqa: F811
    result, times, points = traced(arm, executor, f"300 SPEED 50 JSPEED {SQUARE} {move} -1 $WAIT")
    assert result.status is Status.FINISHED and result.stack == ["I2:0"] * 4, result.console
    start, v = points[0], speeds(times, points)
    for corner in CORNERS[:2]:
        k = int(np.argmin(np.linalg.norm(points - (start + corner), axis=1)))
        assert np.linalg.norm(points[k] - (start + corner)) < 0.5
        assert v[k - 15:k + 15].min() < 2.0                   # it stops there
    assert np.linalg.norm(points[-1] - (start + CORNERS[2])) < 0.2


@pytest.mark.parametrize("move, min_speed", [("ALMOVE", 40.0), ("AJMOVE", 12.0)])
def test_sacc_blends_through_via_points_without_stopping(move, min_speed):
    durations = {}
    for sacc in (0, 20):
        world = World()
        try:
            sim = MotionExecutor(world, real_time_factor=0.0)
            blended = ArmCore(sim, ArmConfig(queue_size=8, initial_joints_deg=WORK))
            assert blended.servo_on().ok
            result, times, points = traced(blended, sim, f"300 SPEED 50 JSPEED {sacc} SACC "
                                                         f"{SQUARE} {move} -1 $WAIT")
        finally:
            world.close()
        assert result.status is Status.FINISHED and result.stack == ["I2:0"] * 5, result.console
        durations[sacc] = result.duration
    start, v = points[0], speeds(times, points)
    moving = np.flatnonzero(v > 0.3 * v.max())
    assert v[moving[0]:moving[-1]].min() > min_speed           # never stops between the ends
    for corner in CORNERS[:2]:                                  # passes within the radius
        assert np.min(np.linalg.norm(points - (start + corner), axis=1)) < 20.0
    assert np.linalg.norm(points[-1] - (start + CORNERS[2])) < 0.2
    assert durations[20] < durations[0] - 0.2


def test_wait_returns_when_the_motion_is_over_or_at_its_timeout(arm, executor):  # noqa: F811
    result = run(arm, executor, "Ar[R8 30 0 0 0 0 0 0] IDRIVE DROP CLOCK 0.2 $WAIT CLOCK "
                                "-1 $WAIT JHERE")
    assert result.status is Status.FINISHED, result.report
    t0, status, t1, done, joints = result.stack
    assert status == "I2:1" and done == "I2:0"
    assert int(t1.split(":")[-1]) - int(t0.split(":")[-1]) == pytest.approx(200, abs=10)
    assert abs(numbers(joints)[0] - 30.0) < 0.05           # it waited for the end of the move


def test_delay_counts_simulated_time_and_stands_still_during_an_interrupt(arm, executor):  # noqa: F811
    plain = run(arm, executor, "CLOCK 0.5 DELAY DROP CLOCK EXCH SUB")
    assert int(plain.stack[-1].split(":")[-1]) == pytest.approx(500, abs=10)
    interrupted = run(arm, executor, "Fn{ 0.3 DELAY DROP END } TACTION 100 TIMER "
                                     "CLOCK 0.5 DELAY DROP CLOCK EXCH SUB")
    assert int(interrupted.stack[-1].split(":")[-1]) == pytest.approx(800, abs=20)


def test_pause_holds_the_arm_until_the_operator_resumes(arm, executor):  # noqa: F811
    seen = []
    result = run(arm, executor, 'Ar[R8 40 0 0 0 0 0 0] IDRIVE DROP 0.3 DELAY DROP '
                                '"check the part" PAUSE -1 $WAIT JHERE', resume_after=1.5,
                 hook=lambda: seen.append((arm.state_word(), np.abs(
                     executor.world.arm_velocities()).max())))
    assert result.status is Status.FINISHED and result.stack[:2] == ["I2:0", "I2:0"]
    assert "PAUSE: check the part" in result.console and result.duration > 1.5
    paused = [speed for word, speed in seen if word & 0x10]
    assert len(paused) > 200 and max(paused[150:]) < 0.01    # decelerated, then held
    assert abs(numbers(result.stack[-1])[0] - 40.0) < 0.05   # and then went on


def test_progress_while_paused_counts_the_instructions_run(arm, executor):  # noqa: F811
    """A PAUSE blocks inside its slice: the count read 0 until the slice ended."""
    program = ProgramRun(arm, '1 2 3 DROP DROP DROP "hold" PAUSE', step=None)
    seen = []

    def step():
        executor.step()
        if arm.device.paused:
            seen.append(program.progress())
            if len(seen) > 50:
                assert arm.resume().ok
    program.host.step = step
    assert program.run().status is Status.FINISHED
    assert seen and {p.state for p in seen} == {"paused"}
    assert {p.instructions for p in seen} == {7}                # 1 2 3 DROP×3 "hold": PAUSE runs


def test_progress_inside_a_function_made_at_run_time_shows_where_it_was_called(
        arm, executor):  # noqa: F811
    """A function made at run time (DECODE1) has no bytes in the program: the progress added
    its missing origin to an offset (a TypeError in every feedback while the program ran it);
    the program counter is now the code that called it."""
    text = '.name g %1000 VAR #g DCL #g "Fn{ 0.2 DELAY END }" #Fn(0) DECODE1 STORE g'
    program = ProgramRun(arm, text, step=None)
    seen = []

    def step():
        executor.step()
        seen.append(program.progress().program_counter)
    program.host.step = step
    assert program.run().status is Status.FINISHED
    code = assemble(text)
    assert code[seen[-1]:] == bytes.fromhex("1000")          # the last code: g


def test_a_long_pause_message_is_shown_cut(arm, executor):  # noqa: F811
    """The console line was cut, but the progress (the action's feedback, at its rate) carried
    the whole message: 8 MiB a message while the program stayed paused."""
    program = ProgramRun(arm, '"' + "x" * 5000 + '" PAUSE', step=None)
    seen = []

    def step():
        executor.step()
        if arm.device.paused:
            seen.append(program.progress())
            assert arm.resume().ok
    program.host.step = step
    assert program.run().status is Status.FINISHED
    assert len(seen[0].message) < 4200 and seen[0].message.endswith("(5000 characters)")


@pytest.mark.parametrize("before", ["servo off", "alarm"])
def test_a_pause_resumed_goes_on_whatever_was_so_before_it(arm, executor, before):  # noqa: F811
    """Only a stop, servo-off or alarm during the pause ends it as an exception: with the servo
    off or an alarm since before the program, a resume ended it as one too, so a program that
    only pauses (I/O, DELAY, PAUSE) could never go on."""
    if before == "servo off":
        assert arm.servo_off().ok
    else:
        assert arm.set_speed_joint(50).ok and arm.move_ptp_joint_rel([20, 0, 0, 0, 0, 0, 0]).ok
        for _ in range(60):
            executor.step()
        z = arm.tool_pose(arm.feedback_joints)[2, 3] * 1000.0
        assert arm.set_soft_limit_cartesian((2000, -2000), (2000, -2000), (2000, z + 500.0)).ok
        for _ in range(250):
            executor.step()
        assert arm.alarms
    result = run(arm, executor, '1 "check the part" PAUSE', resume_after=0.5)
    assert result.status is Status.FINISHED, result.report
    assert result.stack == ["1", "I2:0"]


def test_the_shown_stack_counts_characters_not_bytes():
    """A byte can take four characters (\\xNN): 1000 items of 64 KiB (DUP) made 262 MB."""
    big, small = Str(b"\x00" * RESULT_ITEM), Str(b"\x00" * 1000)
    shown = shown_stack([big] * 1000)
    assert set(shown) == {f"Str<{RESULT_ITEM} bytes, not shown>"}
    shown = shown_stack([small] * 1000)
    assert shown[-1] == format_value(small) and shown[0] == "Str<1000 bytes, not shown>"
    assert sum(map(len, shown)) < RESULT_CHARS + 40 * 1000
    shown = shown_stack([Num(I2, 42), Str(b"hello"), *[big] * 20, Num(I2, 7)])
    assert shown[:2] == ["I2:42", format_value(Str(b"hello"))] and shown[-1] == "I2:7"
    sent = [encode_value(small)] * 1000                     # RESULT in a loop: 120 MB of output
    shown = shown_output(sent)
    assert shown[0] == format_value(small) and shown[-1].endswith("bytes sent, not shown>")
    assert sum(map(len, shown)) < RESULT_CHARS + 40 * 1000


def arm_rest_after(executor, arm, since):  # noqa: F811
    """Simulated seconds from `since` until the measured joints are still."""
    t0 = executor.world.time
    while np.abs(executor.world.arm_velocities()).max() > 0.005:
        executor.step()
        assert executor.world.time - t0 < 5.0
    return executor.world.time - since


@pytest.mark.parametrize("event, kind", [
    ("soft limit", K.OUT_OF_OPERATING_REGION), ("stop", K.ROBOT_ERROR),
    ("servo off", K.SERVO_ERROR), ("cancel", K.STOPPED)])
def test_a_motion_error_or_cancel_stops_the_program_and_the_arm(arm, executor, event, kind):  # noqa: F811
    program = ProgramRun(arm, "80 JSPEED DROP Ar[R8 0 40 0 0 0 0 0] IDRIVE DROP "
                              "Ar[R8 0 -40 0 0 0 0 0] IDRIVE DROP -1 $WAIT", step=None)
    when = {}

    def step():
        executor.step()
        if "at" not in when and executor.world.time > 0.6:
            when["at"] = executor.world.time
            if event == "soft limit":
                z = arm.tool_pose(arm.feedback_joints)[2, 3] * 1000.0
                assert arm.set_soft_limit_cartesian((2000, -2000), (2000, -2000),
                                                    (2000, z - 2.0)).ok
            elif event == "stop":
                assert arm.stop().ok
            elif event == "servo off":
                assert arm.servo_off().ok
            else:
                program.cancel()
    program.host.step = step
    result = program.run()
    assert result.status is (Status.CANCELED if event == "cancel" else Status.EXCEPTION)
    assert result.error.kind is kind, result.report
    assert result.stack == ["-1"]                           # stopped in $WAIT
    assert not arm.device.busy                              # the run ends with the arm at rest
    assert arm_rest_after(executor, arm, when["at"]) < arm.accel_time_joint + 0.25


@pytest.mark.parametrize("event, kind", [("stop", K.ROBOT_ERROR), ("servo off", K.SERVO_ERROR)])
def test_a_stop_is_seen_by_a_program_with_another_clients_motion_queued_behind_it(
        arm, executor, event, kind):  # noqa: F811
    """A stop retires the motions queued behind the current one at once, while the current one
    (the program's) still decelerates: its $WAIT must not take it for completed and go on."""
    t0, done = executor.world.time, {}
    assert arm.set_speed_joint(50).ok

    def hook():
        if "queued" not in done and arm.device.moving:
            done["queued"] = arm.move_ptp_joint_rel([0.0] * 6 + [5.0])
        elif "stopped" not in done and executor.world.time - t0 > 0.5:
            done["stopped"] = arm.stop() if event == "stop" else arm.servo_off()
    result = run(arm, executor, "80 JSPEED DROP Ar[R8 40 0 0 0 0 0 0] IDRIVE DROP -1 $WAIT DROP "
                                "0.2 DELAY DROP Ar[R8 -80 0 0 0 0 0 0] IDRIVE DROP -1 $WAIT",
                 hook=hook)
    assert done["queued"].ok and done["stopped"].ok
    assert result.status is Status.EXCEPTION and result.error.kind is kind, result.report
    assert "motion 1 of the program" in result.report       # stopped in the first $WAIT
    arm_rest_after(executor, arm, executor.world.time)
    assert np.degrees(arm.feedback_joints[0]) > WORK[0] + 1.0   # the second move never ran


def test_a_program_exception_stops_the_arm(arm, executor):  # noqa: F811
    result = run(arm, executor, "Ar[R8 60 0 0 0 0 0 0] IDRIVE DROP 0.5 DELAY DROP 1 0 DIV")
    assert result.status is Status.EXCEPTION and result.error.kind is K.DIVISION_BY_ZERO
    assert "DIV" in result.report and arm.device.queue_length == 0
    since = executor.world.time
    assert arm_rest_after(executor, arm, since) < arm.accel_time_joint + 0.25
    assert abs(np.degrees(arm.feedback_joints[0]) - 60.0) > 10.0   # it did not go on


def test_a_full_queue_makes_the_program_wait(arm, executor):  # noqa: F811
    moves = " ".join(["Ar[R8 2 0 0 0 0 0 0] IDRIVE"] * 12)
    result = run(arm, executor, f"100 JSPEED DROP {moves} -1 $WAIT JHERE")
    assert result.status is Status.FINISHED and result.stack[:13] == ["I2:0"] * 13
    assert abs(numbers(result.stack[-1])[0] - 24.0) < 0.05


def test_program_and_service_motions_run_in_the_order_sent(arm, executor):  # noqa: F811
    sent = {}

    def hook():
        if "id" not in sent and arm.device.last_id >= 1:
            sent["id"] = arm.move_ptp_joint_rel([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 10.0])
    assert arm.set_speed_joint(50).ok
    labels = []
    executor.after_step(lambda world: labels.append(arm.motion_status()[1]))
    result = run(arm, executor, "Ar[R8 10 0 0 0 0 0 0] IDRIVE DROP 0.1 DELAY DROP "
                                "Ar[R8 0 -10 0 0 0 0 0] IDRIVE DROP -1 $WAIT JHERE", hook=hook)
    assert result.status is Status.FINISHED and sent["id"].ok
    order = [label for i, label in enumerate(labels) if label and label != labels[i - 1]]
    assert order == ["IDRIVE", "move_ptp_joint_rel", "IDRIVE"]
    assert np.allclose(numbers(result.stack[-1]), np.add(WORK, [10, -10, 0, 0, 0, 0, 10]),
                       atol=0.05)


def test_status_port_and_outputs(arm, executor):  # noqa: F811
    result = run(arm, executor, "16 DIN 3 5 DOUT 3 DIN 16 1 DOUT")
    assert result.stack == ["I2:17", "I2:5"]                 # servo on, hand closed
    assert any("output port 16 does not exist" in line for line in result.console)


def test_done_sees_the_abnormal_end_and_the_program_still_stops(arm, executor):  # noqa: F811
    seen = []

    def hook():
        if not seen and executor.world.time > 0.5:
            seen.append(arm.stop())
    result = run(arm, executor, ".name poll %1000 VAR #poll DCL "
                                "#poll FDEF Fn{ top: $DONE DUP 0 GT >top BRT END } "
                                "80 JSPEED DROP Ar[R8 0 40 0 0 0 0 0] IDRIVE DROP poll",
                 hook=hook)
    assert seen and result.status is Status.EXCEPTION and result.error.kind is K.ROBOT_ERROR
    assert result.stack[-1] == "I2:-1"                        # $DONE gave the abnormal end


TIMED = "CLOCK {move} DROP -1 $WAIT DROP CLOCK EXCH SUB"
J7_60 = ("Ar[R8 0 0 0 0 0 0 60] IDRIVE", 60 / 135.0)      # J7: 60° at most 135°/s
DOWN_100 = ("HERE Vec(0 0 -100) DEV ALMOVE", 100 / 500.0)  # 100 mm at most 500 mm/s


@pytest.mark.parametrize("settings, move, ratio, ramp", [
    (["50 JSPEED"], J7_60, 0.5, 0.3), (["25 JSPEED"], J7_60, 0.25, 0.3),
    (["50 JSPEED", "1.0 ACCEL2"], J7_60, 0.5, 1.0),
    (["50 JSPEED", "0.8 DECEL2"], J7_60, 0.5, 0.8),
    (["50 JSPEED", "0.2 ACCEL2", "0.5 DECEL2"], J7_60, 0.5, 0.5),
    (["50 JSPEED", "50 ACCEL1"], J7_60, 0.5, 0.2),
    (["50 JSPEED", "100 ACCEL1", "25 DECEL1"], J7_60, 0.5, 0.4),
    (["200 SPEED"], DOWN_100, 0.4, 0.3), (["50 SPEED"], DOWN_100, 0.1, 0.3),
    (["200 SPEED", "0.6 ACCEL2"], DOWN_100, 0.4, 0.6)])
def test_speed_and_acceleration_settings_time_the_moves(arm, executor, settings, move, ratio,  # noqa: F811
                                                        ramp):
    """A trapezoid: max(cruise, ramp) + ramp, the cruise at the set fraction of the maximum."""
    program = " ".join(f"{setting} DROP" for setting in settings)
    result = run(arm, executor, f"{program} {TIMED.format(move=move[0])}")
    assert result.status is Status.FINISHED, result.report
    seconds = max(move[1] / ratio, ramp) + ramp
    assert int(result.stack[-1].split(":")[-1]) / 1000.0 == pytest.approx(seconds, abs=0.02)


@pytest.mark.parametrize("setting", ["0.001 ACCEL1", "0.001 DECEL1"])
def test_a_stop_ends_a_move_of_the_smallest_acceleration_within_the_longest_ramp(
        arm, executor, setting):  # noqa: F811
    """ACCEL1/DECEL1 take any percentage above 0: 0.001 % made a ramp of 10 000 s, over which
    a stop decelerated; the arm never came to rest and every later move was discarded. A stop
    takes at most MAX_RAMP (the longest ramp ACCEL2 and the ports allow)."""
    stopped = []

    def hook():
        if not stopped and arm.device.busy:
            stopped.append(executor.world.time)
            assert arm.stop().ok
    result = run(arm, executor, f"50 JSPEED DROP {setting} DROP {J7_60[0]} DROP -1 $WAIT",
                 hook=hook)
    assert result.status is Status.EXCEPTION and result.error.kind is K.ROBOT_ERROR
    assert not arm.device.busy and executor.world.time - stopped[0] <= MAX_RAMP + 0.1


def test_a_pose_sequence_with_a_refused_pose_queues_none_of_it(arm, executor):  # noqa: F811
    """The sequence is one command: its last pose out of reach leaves the arm where it was."""
    far = "HERE Vec(0 150 0) DEV HERE Vec(0 0 -50) DEV HERE Vec(0 0 2000) DEV 3 #Pm(120) CONSA"
    for move in ("AJMOVE", "ALMOVE"):
        result = run(arm, executor, f"JHERE {far} {move} -1 $WAIT DROP JHERE")
        assert result.status is Status.FINISHED and result.stack[1] == "I2:2", result.console
        assert arm.device.last_id == 0
        assert np.allclose(numbers(result.stack[0]), numbers(result.stack[2]), atol=1e-3)


def test_a_program_waits_when_another_client_took_the_room_it_saw(arm, executor):  # noqa: F811
    """Between the program's look at the queue and its queueing, another client filled it: the
    program waits for room (nothing of its sequence queued meanwhile), then queues all of it."""
    queue_together, filled = arm.all_or_nothing, []

    def racing():
        if not filled:
            filled.extend(arm.move_ptp_joint_rel([0.0] * 6 + [0.1]) for _ in range(7))
        return queue_together()
    arm.all_or_nothing = racing
    assert arm.set_speed_joint(50).ok
    result = run(arm, executor, f"{SQUARE} AJMOVE -1 $WAIT HERE")
    assert all(r.ok for r in filled), filled
    assert result.status is Status.FINISHED and result.stack[0] == "I2:0", result.console
    assert arm.device.last_id == 7 + 3 and arm.device.completed == 10


def test_a_fault_outside_the_vm_stops_the_program_and_the_arm(arm, executor):  # noqa: F811
    """Any failure, not only the program's exceptions, ends the run as an exception and stops
    the arm (it used to escape the run, which stayed "running" while the arm moved on)."""
    run_ = ProgramRun(arm, "Ar[R8 60 0 0 0 0 0 0] IDRIVE DROP -1 $WAIT", step=executor.step)
    check, t0 = run_.host.check, executor.world.time

    def faulty(vm):
        if executor.world.time - t0 > 0.3:
            raise RuntimeError("a bug")
        check(vm)
    run_.host.check = faulty
    result = run_.run()
    assert result.status is Status.EXCEPTION and result.error.kind is K.CONTROLLER_ERROR
    assert "RuntimeError: a bug" in result.report and run_.host.state == "exception"
    assert not arm.device.busy and abs(np.degrees(arm.feedback_joints[0]) - WORK[0] - 60) > 10


@pytest.mark.parametrize("event, kind", [("stop", K.ROBOT_ERROR), ("servo off", K.SERVO_ERROR)])
def test_a_stop_during_pause_ends_the_program(arm, executor, event, kind):  # noqa: F811
    """A stop or servo_off ended the pause as a resume would: PAUSE pushed 0 and the program
    drove the arm on after the operator's stop."""
    done = {}

    def hook():
        if "stopped" not in done and arm.device.paused:
            done["stopped"] = arm.stop() if event == "stop" else arm.servo_off()
    q0 = arm.feedback_joints.copy()
    result = run(arm, executor, '"hold" PAUSE DROP Ar[R8 30 0 0 0 0 0 0] IDRIVE -1 $WAIT',
                 hook=hook)
    assert done["stopped"].ok
    assert result.status is Status.EXCEPTION and result.error.kind is kind, result.report
    assert "PAUSE" in result.report
    assert np.allclose(arm.feedback_joints, q0, atol=1e-3)           # it did not go on


def test_the_result_keeps_its_size_whatever_the_program_holds(arm, executor):  # noqa: F811
    """13 copies (DUP) of an 8 MB string put 436 MB of text into the result, and a traced
    4 MiB string, ten times, 168 MB of console lines; the data limit counts neither."""
    big = ('.name f %1000 .name g %1001 .name i %1002 VAR #f #g #i DCL '
           '#f FDEF Fn{ "\\x00\\x01\\x02\\x03\\x04\\x05\\x06\\x07" top: DUP CONC DUP LNG 4000000 '
           'LT >top BRT END } #i 0 STORE TRON '
           '#g FDEF Fn{ top: DUP TRACE #i i INC STORE i 10 LT >top BRT END } f g ')
    result = run(arm, executor, big + "DUP " * 12 + "1 2")
    assert result.status is Status.FINISHED, result.report
    assert len(result.stack) == 15 and result.stack[-1] == "2"
    assert result.stack[0] == "Str<4194304 bytes, not shown>"
    assert sum(map(len, result.console)) < 2 << 20 and len(result.console) > 1
    result = run(arm, executor, "1 " * 1500)
    assert result.stack[0] == "… 500 items below not shown" and len(result.stack) == 1001


def test_a_program_is_loaded_on_its_own_thread_and_bounded(arm, executor):  # noqa: F811
    """Loading ran on the caller's thread (the goal plane: a 2 MB text held a ~/move cancel for
    7 s); a program longer than 1 MiB is INVALID."""
    program = ProgramRun(arm, "1 DROP " * 200000, step=executor.step)    # not loaded yet
    result = program.run()
    assert result.status is Status.INVALID and "at most 1048576" in result.report


def test_a_servo_off_is_a_servo_error_also_with_the_servo_on_again(arm, executor):  # noqa: F811
    """The kind came from the servo at the time the program looked: a servo_on right after the
    servo_off made it "other robot error"."""
    t0, done = executor.world.time, {}

    def hook():
        if "off" not in done and executor.world.time - t0 > 0.3:
            done["off"] = arm.servo_off()
        elif "off" in done and "on" not in done:
            done["on"] = arm.servo_on()
    result = run(arm, executor, "50 JSPEED DROP Ar[R8 40 0 0 0 0 0 0] IDRIVE DROP -1 $WAIT",
                 hook=hook)
    assert done["off"].ok and done["on"].ok
    assert result.status is Status.EXCEPTION and result.error.kind is K.SERVO_ERROR, result.report
