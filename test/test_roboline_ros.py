"""RoboLine over DDS: the examples (examples/programs/, each with its taught data) run end to end
through ~/run_program's source fields; feedback carries the source line and an exception names
it; a program that does not compile is INVALID with file:line:column; ~/check_program reports
every move without moving the arm and cuts an endless program; breakpoints in the goal and
~/program_debug (set, clear, step, continue) hold the program; ~/program_variable reads it."""
from __future__ import annotations

import math
from pathlib import Path

import pytest
from acti_msgs import srv
from acti_msgs.action import RunProgram
from acti_msgs.msg import CheckedMove
from action_msgs.msg import GoalStatus

from ros_harness import Actions, node_fixture, wait_until
from test_arm_ros import ARM, call

arm_node = node_fixture("acti_middle_node")
ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples" / "programs"
POINTS = (EXAMPLES / "cell.pts").read_text()
READY_MM = (663.5, 0.0, 463.3)
R = RunProgram.Result
D = srv.ProgramDebug.Request


@pytest.fixture(scope="module")
def programs(ros, arm_node):
    return Actions(ros, RunProgram, ARM + "run_program")


def ready(ros):
    call(ros, "clear_alarms", srv.ClearAlarms)
    assert call(ros, "servo_on", srv.ServoON).return_id.id == 0


def variable(ros, name: str):
    """~/program_variable (its field `name` is the harness's call parameter too)."""
    client = ros.node.create_client(srv.ProgramVariable, ARM + "program_variable")
    assert client.wait_for_service(timeout_sec=10.0)
    future = client.call_async(srv.ProgramVariable.Request(name=name))
    assert ros.wait(future, 30.0)
    ros.node.destroy_client(client)
    return future.result()


def printed(result) -> list[list[str]]:
    return [line.strip('"').split() for line in result.output]


EXAMPLE_CHECKS = {
    "pick_and_place.rbl": lambda out: out[0][:2] == ["done", "0"] and float(out[0][2]) < 0.5,
    "palletising.rbl": lambda out: out[0][:3] == ["placed", "6", "0"] and float(out[0][3]) < 0.5,
    "subroutine.rbl": lambda out: out[0][:2] == ["traced", "960"] and float(out[0][2]) < 0.5,
    "io_handshake.rbl": lambda out: out[0][:3] == ["cycles", "3", "0"] and float(out[0][3]) < 0.5,
}


def test_every_example_is_checked():
    assert sorted(p.name for p in EXAMPLES.glob("*.rbl")) == sorted(EXAMPLE_CHECKS)
    assert all((EXAMPLES / name).with_suffix(".pts").exists() for name in EXAMPLE_CHECKS)


@pytest.mark.parametrize("name", sorted(EXAMPLE_CHECKS))
def test_examples_run_end_to_end(ros, programs, name):
    ready(ros)
    feedback = []
    path = EXAMPLES / name
    handle = programs.send(lambda f: feedback.append(f.feedback), source=path.read_text(),
                           source_name=name, points=path.with_suffix(".pts").read_text())
    status, result = programs.result(handle)
    assert status == GoalStatus.STATUS_SUCCEEDED and result.status == R.FINISHED, result.exception
    assert EXAMPLE_CHECKS[name](printed(result)), (result.output, result.console)
    code_lines = {i for i, text in enumerate(path.read_text().splitlines(), 1)
                  if text.strip().upper().startswith(("MOVE", "APPROACH", "WAIT", "SQUARE"))}
    assert {f.line for f in feedback} & code_lines, [f.line for f in feedback]
    pos = call(ros, "get_feedback_pos_cartesian", srv.GetFeedbackPosCartesian).pos.car_pos
    assert math.dist((pos[3], pos[7], pos[11]), READY_MM) < 1.0


def test_an_exception_names_its_source_line_and_bad_source_is_invalid(ros, programs):
    ready(ros)
    status, result = programs.result(programs.send(
        source="MOVE P, READY\nWAIT\nMOVE L, HOME + VEC(0, 0, 3000)\n", source_name="far.rbl",
        points=POINTS))
    assert status == GoalStatus.STATUS_ABORTED and result.status == R.EXCEPTION
    assert result.exception_line == 3
    assert result.exception.startswith("far.rbl:3: MOVE L, HOME + VEC(0, 0, 3000): the command "
                                       "was refused"), result.exception
    status, result = programs.result(programs.send(source="DIM a AS INT\nIF a = THEN\nEND IF\n",
                                                   source_name="bad.rbl"))
    assert status == GoalStatus.STATUS_ABORTED and result.status == R.INVALID
    assert result.exception_line == 2 and result.exception.startswith(
        "bad.rbl:2:8: error: unexpected 'THEN'"), result.exception
    assert result.exception.split("\n")[2].index("^") == 4 + 7
    status, result = programs.result(programs.send(source="PRINT P1\n", points="POSE P1 = 1\n"))
    assert result.status == R.INVALID and "(points):1:" in result.exception


CHECKED = """MOVE P, READY
WAIT
ON ERROR CONTINUE
MOVE L, HOME + VEC(0, 0, -100)
MOVE L, HOME + VEC(0, 0, 2000)
MOVE P, HOME + VEC(3000, 0, 0)
"""


def test_check_reports_every_move_without_moving_the_arm(ros, arm_node):
    ready(ros)
    before = call(ros, "get_feedback_pos_joint", srv.GetFeedbackPosJoint).pos
    answer = call(ros, "check_program", srv.CheckProgram, source=CHECKED, source_name="c.rbl",
                  points=POINTS)
    assert [(m.line, m.command, m.verdict) for m in answer.moves] == [
        (1, "ADRIVE", CheckedMove.REACHABLE), (4, "ALMOVE", CheckedMove.REACHABLE),
        (5, "ALMOVE", CheckedMove.OUTSIDE_SOFT_LIMIT), (6, "AJMOVE", CheckedMove.UNREACHABLE)]
    assert answer.moves[1].duration > 0.3 and not answer.success and not answer.cut
    assert answer.total_time >= answer.moves[0].duration + answer.moves[1].duration
    after = call(ros, "get_feedback_pos_joint", srv.GetFeedbackPosJoint).pos
    assert max(abs(a - b) for a, b in zip(before, after)) < 1e-3      # degree: held, not moved
    endless = call(ros, "check_program", srv.CheckProgram, budget=5.0, points=POINTS,
                   source="WHILE 1\n  MOVE P, READY\n  MOVE L, HOME + VEC(0, 0, -50)\nWEND\n")
    assert endless.cut and "cut after 5 s" in endless.message and endless.total_time <= 5.1
    bad = call(ros, "check_program", srv.CheckProgram, source="MOVE Q, HOME", points=POINTS)
    assert not bad.success and "1:6: error: MOVE takes the interpolation first" in bad.message
    good = call(ros, "check_program", srv.CheckProgram, points=POINTS,
                source=(EXAMPLES / "pick_and_place.rbl").read_text())
    assert good.success and all(m.verdict == CheckedMove.REACHABLE for m in good.moves)
    assert good.total_time > 5.0


DEBUGGED = """DIM n AS INT
MOVE P, READY
FOR n = 1 TO 3
  MOVE L, HOME + VEC(0, 0, -20 * n)
  PRINT n
NEXT
PRINT "end"
"""


def test_breakpoints_step_continue_and_variables(ros, programs):
    ready(ros)
    feedback = []
    debug = lambda command, lines=(): call(ros, "program_debug", srv.ProgramDebug,  # noqa: E731
                                           command=command, lines=list(lines))
    handle = programs.send(lambda f: feedback.append(f.feedback), source=DEBUGGED,
                           points=POINTS, breakpoints=[5])

    def held_at(line: int) -> bool:
        answer = debug(D.SET)
        return answer.state == "at breakpoint" and answer.line == line
    assert wait_until(lambda: held_at(5), 60.0)
    assert call(ros, "get_state", srv.GetState).state & 0x02 == 0      # its motion has ended
    assert ros.spin_until(lambda: any(f.state == "at breakpoint" and f.line == 5
                                      and list(f.breakpoints) == [5] for f in feedback), 30.0)
    value = variable(ros, "n")
    assert value.success and (value.type, value.value) == ("int", "I4:1")
    missing = variable(ros, "m")
    assert not missing.success and "m is no variable" in missing.message
    assert list(debug(D.SET, [7]).breakpoints) == [5, 7]
    refused = debug(D.SET, [1])
    assert not refused.success and refused.message == "no code on line 1"
    assert debug(D.STEP).success
    assert wait_until(lambda: held_at(6), 30.0)
    assert list(debug(D.CLEAR, [5]).breakpoints) == [7]
    assert debug(D.CONTINUE).success
    assert wait_until(lambda: held_at(7), 60.0)
    assert variable(ros, "N").value == "I4:4"
    debug(D.CLEAR)
    assert list(debug(D.CONTINUE).breakpoints) == []
    status, result = programs.result(handle)
    assert result.status == R.FINISHED and printed(result) == [["1"], ["2"], ["3"], ["end"]]
    idle = debug(D.STEP)
    assert not idle.success and idle.message == "no RoboLine program runs"


def test_step_from_the_first_line_and_cancel_at_a_breakpoint(ros, programs):
    ready(ros)
    handle = programs.send(source="PRINT 1\nPRINT 2\n", step=True)
    debug = lambda command: call(ros, "program_debug", srv.ProgramDebug,  # noqa: E731
                                 command=command)
    assert wait_until(lambda: debug(D.SET).line == 1 and debug(D.SET).state == "at breakpoint",
                      30.0)
    debug(D.STEP)
    assert wait_until(lambda: debug(D.SET).line == 2, 30.0)
    programs.spin(handle.cancel_goal_async())
    status, result = programs.result(handle)
    assert status == GoalStatus.STATUS_CANCELED and printed(result) == [["1"]]
