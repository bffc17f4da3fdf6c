"""~/run_program over DDS: the robot examples run through the action and end where they should;
cancel mid-motion stops the arm within its deceleration time; an exception (the program's, or a
stop from a service) is reported and the arm stops; one program at a time; the command line."""
import math
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest
from acti_msgs import srv
from acti_msgs.action import RunProgram
from acti_msgs.msg import ArmState
from action_msgs.msg import GoalStatus
from rosgraph_msgs.msg import Clock
from service_msgs.msg import ServiceEventInfo

from acti_record.timing import ClockMap
from ros_harness import Actions, node_fixture, wait_until
from test_arm_ros import ARM, call
from strolic.text import assemble

arm_node = node_fixture("acti_middle_node", "state_rate_hz:=100.0")   # 40 ms simulated
ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples" / "strolic"
READY_MM = (663.5, 0.0, 463.3)    # the control point of the examples' ready posture
ACCEL_TIME = 0.3                  # the arm's accel/decel time (config/acti_ros2.yaml)
CONTROL_PERIOD_S = 1 / 250.0      # the job's default rate_hz
SETTLE_S = 0.05                   # the measured joints follow a stopped set-point 21-38 ms more
R = RunProgram.Result


@pytest.fixture(scope="module")
def programs(ros, arm_node):
    return Actions(ros, RunProgram, ARM + "run_program")


@pytest.fixture(scope="module")
def states(ros, arm_node):
    """(stamp [s, simulated], state word) of every ~/state message from here on (all of them:
    with the latest only, a busy test process missed the first at rest)."""
    seen = []
    ros.node.create_subscription(
        ArmState, ARM + "state",
        lambda m: seen.append((m.stamp.sec + 1e-9 * m.stamp.nanosec, m.state)), 1000)
    return seen


@pytest.fixture(scope="module")
def job_clock(ros, arm_node):
    """The job's simulated time at moments of its wall clock (its /clock messages)."""
    clock = ClockMap()
    ros.node.create_subscription(
        Clock, "/clock",
        lambda m, info: clock.add(info["source_timestamp"], m.clock.sec * 10**9 + m.clock.nanosec),
        1000)
    return clock


@pytest.fixture(scope="module")
def cancels_answered(ros, arm_node):
    """When the job answered each cancel of ~/run_program [ns, its wall clock]: its service
    event (service introspection, on by default)."""
    answered = []
    event = RunProgram.Impl.CancelGoalService.Event
    events = ros.node.create_subscription(
        event, ARM + "run_program/_action/cancel_goal/_service_event",
        lambda e: answered.append(e.info.stamp.sec * 10**9 + e.info.stamp.nanosec)
        if e.info.event_type == ServiceEventInfo.RESPONSE_SENT else None, 100)
    assert ros.spin_until(lambda: events.get_publisher_count() > 0, 30.0)
    return answered


def ready(ros):
    call(ros, "clear_alarms", srv.ClearAlarms)
    assert call(ros, "servo_on", srv.ServoON).return_id.id == 0


def moving(ros):
    return call(ros, "get_state", srv.GetState).state & 0x02


def value(item):
    return float(item.split(":")[-1])


EXAMPLE_CHECKS = {
    "robot_pick_and_place.sasm": lambda s: s[0] == "I2:0" and value(s[1]) < 0.5,
    "robot_palletising.sasm": lambda s: s[:2] == ["I2:0", "I2:6"] and value(s[2]) < 0.5,
    "robot_blended_via_points.sasm":
        lambda s: value(s[0]) > value(s[1]) + 300 and s[2] == "I2:0" and value(s[3]) < 0.5,
    "robot_io_loop.sasm": lambda s: s[:3] == ["I2:0", "I2:3", "I2:3"] and value(s[3]) < 0.5,
}


def test_every_robot_example_is_checked():
    assert sorted(p.name for p in EXAMPLES.glob("robot_*.sasm")) == sorted(EXAMPLE_CHECKS)


@pytest.mark.parametrize("name", sorted(EXAMPLE_CHECKS))
def test_examples_run_through_the_action_and_end_where_they_should(ros, programs, name):
    ready(ros)
    feedback = []
    handle = programs.send(lambda f: feedback.append(f.feedback),
                           text=(EXAMPLES / name).read_text())
    status, result = programs.result(handle)
    assert status == GoalStatus.STATUS_SUCCEEDED and result.status == R.FINISHED, result.exception
    assert EXAMPLE_CHECKS[name](result.stack), (result.stack, result.console)
    assert result.duration > 1.0 and result.instructions > 50
    assert any(f.motion_label == "ALMOVE" and f.program_counter > 0 for f in feedback)
    pos = call(ros, "get_feedback_pos_cartesian", srv.GetFeedbackPosCartesian).pos.car_pos
    assert math.dist((pos[3], pos[7], pos[11]), READY_MM) < 1.0


def test_cancel_mid_motion_stops_the_arm_within_its_deceleration_time(ros, programs, states,
                                                                      job_clock, cancels_answered):
    """Timed on the job's own clock: from its answer to the cancel (the stop is in force then)
    to the last ~/state message that says moving. The test's wall clock added its own
    scheduling, four times over at the job's real_time_factor of 4 (and a ~/state subscription
    that kept only the latest message missed the first at rest)."""
    ready(ros)
    feedback = []
    handle = programs.send(lambda f: feedback.append(f.feedback),
                           text="40 JSPEED DROP Ar[R8 0 0 0 0 0 0 -150] IDRIVE DROP -1 $WAIT")
    assert ros.spin_until(lambda: any(f.motion_label == "IDRIVE" and f.progress > 0.2
                                       for f in feedback) and states and states[-1][1] & 0x02,
                      30.0)
    answered = len(cancels_answered)
    programs.spin(handle.cancel_goal_async())
    status, result = programs.result(handle)
    assert status == GoalStatus.STATUS_CANCELED and result.status == R.CANCELED
    assert result.exception_kind == "stopped by the operator" and result.stack == ["-1"]
    # answered once the arm is at rest: a program sent now is not discarded by that stop
    assert not call(ros, "get_state", srv.GetState).state & 0x02
    assert ros.spin_until(lambda: len(cancels_answered) > answered, 10.0)
    stopped_at = job_clock.sim_at(cancels_answered[answered]) * 1e-9
    assert ros.spin_until(lambda: any(t > stopped_at and not word & 0x02 for t, word in states),
                          10.0)
    last_moving = max(t for t, word in states if word & 0x02)
    # the deceleration, one control period, the joints' settling onto the set-point at rest
    # (the word says moving meanwhile) and the clock map's resolution (a /clock period)
    allowed = ACCEL_TIME + CONTROL_PERIOD_S + SETTLE_S + job_clock.period_ns() * 1e-9
    assert last_moving - stopped_at <= allowed, (last_moving - stopped_at, allowed)
    pos = call(ros, "get_feedback_pos_joint", srv.GetFeedbackPosJoint).pos
    assert pos[6] > -140.0                                  # it did not go on to the end


def test_an_exception_is_reported_and_the_arm_stops(ros, programs):
    ready(ros)
    text = "30 JSPEED DROP Ar[R8 40 0 0 0 0 0 0] IDRIVE DROP 0.3 DELAY DROP 1 0 DIV"
    start = call(ros, "get_feedback_pos_joint", srv.GetFeedbackPosJoint).pos[0]
    status, result = programs.result(programs.send(text=text))
    assert status == GoalStatus.STATUS_ABORTED and result.status == R.EXCEPTION
    assert result.exception_kind == "division by zero" and "in DIV" in result.exception
    code = assemble(text)
    assert result.exception_offset == len(code) - 2          # DIV is the last code
    assert wait_until(lambda: not moving(ros), 5.0)
    end = call(ros, "get_feedback_pos_joint", srv.GetFeedbackPosJoint).pos[0]
    assert 1.0 < end - start < 30.0                          # stopped on the way


def test_a_stop_from_a_service_stops_the_program(ros, programs):
    ready(ros)
    handle = programs.send(text="30 JSPEED DROP Ar[R8 -40 0 0 0 0 0 0] IDRIVE DROP -1 $WAIT")
    assert wait_until(lambda: moving(ros), 10.0)
    assert call(ros, "stop", srv.Stop).return_id.id == 0
    status, result = programs.result(handle)
    assert result.status == R.EXCEPTION and result.exception_kind == "other robot error"
    assert "of the program was discarded: stop" in result.exception, result.exception


def test_one_program_at_a_time_and_a_program_that_does_not_load(ros, programs):
    ready(ros)
    first = programs.send(text="0.5 DELAY")
    second = programs.spin(programs.client.send_goal_async(RunProgram.Goal(text="1 2 ADD")))
    assert not second.accepted
    status, result = programs.result(first)
    assert result.status == R.FINISHED and result.stack == ["I2:0"]
    status, result = programs.result(programs.send(text="1 FROB"))
    assert status == GoalStatus.STATUS_ABORTED and result.status == R.INVALID
    assert "FROB" in result.exception
    code = assemble('HERE LOC DESTV DROP DROP "done" RESULT')     # as code, not text
    status, result = programs.result(programs.send(code=list(code)))
    assert result.status == R.FINISHED and result.output == ['"done"']
    assert result.stack == ["R4:1.0"] or result.stack[0].startswith("R4:")


def test_command_line_runs_a_file_and_shows_its_progress(arm_node):
    out = subprocess.run([sys.executable, "-m", "acti_middle_node.run_program",
                          str(EXAMPLES / "robot_blended_via_points.sasm")],
                         cwd=ROOT, capture_output=True, text=True, timeout=120,
                         env=dict(os.environ))
    assert out.returncode == 0, out.stdout + out.stderr
    assert "ALMOVE" in out.stdout and "stack: I4:" in out.stdout
    assert "finished after" in out.stdout


def test_command_line_ctrl_c_cancels_the_run(ros, arm_node):
    ready(ros)
    cli = subprocess.Popen([sys.executable, "-m", "acti_middle_node.run_program",
                            str(EXAMPLES / "robot_palletising.sasm")],
                           cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                           env=dict(os.environ))
    try:
        first = cli.stdout.readline()                        # a progress line: it runs
        assert first.startswith("@"), first
        cli.send_signal(signal.SIGINT)
        out, _ = cli.communicate(timeout=60)
    finally:
        if cli.poll() is None:
            cli.kill()
    assert cli.returncode == 2, out
    assert "canceled after" in out and "stopped by the operator" in out
    assert wait_until(lambda: not moving(ros), 5.0)


def test_command_line_ctrl_c_while_waiting_for_the_node_is_one_line(ros, arm_node):
    """Before anything was sent (a wrong --node): a KeyboardInterrupt traceback and exit 130."""
    cli = subprocess.Popen([sys.executable, "-m", "acti_middle_node.run_program", "--node",
                            "/nobody", str(EXAMPLES / "robot_palletising.sasm")],
                           cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                           env=dict(os.environ))
    try:       # its node is up: it waits for /nobody/run_program
        assert ros.spin_until(lambda: "run_program" in ros.node.get_node_names(), 30.0)
        cli.send_signal(signal.SIGINT)
        out, _ = cli.communicate(timeout=30)
    finally:
        if cli.poll() is None:
            cli.kill()
    assert cli.returncode == 2 and out.strip() == "interrupted", out
