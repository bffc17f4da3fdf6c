"""A RoboLine program on the simulated arm with its source map (ROS-free): progress and the
exception name source lines; breakpoints hold the program once its motions have ended; step
and continue; variables by name; the check before motion runs a fresh arm and leaves the live
one where it is."""
from __future__ import annotations

import numpy as np
import pytest

from acti_motion.arm.core import ArmConfig, ArmCore
from acti_motion.programs.check import OUTSIDE_SOFT_LIMIT, REACHABLE, UNREACHABLE, check_program
from acti_motion.programs.run import ProgramRun, Status
from roboline import Source, compile_source
from sim_fixtures import executor  # noqa: F401

WORK = (0.0, 45.0, 0.0, -90.0, 0.0, 45.0, 0.0)
PROGRAM = """DIM n AS INT
DIM ready AS POSE
SPEED 250
MOVE P, JOINT(0, 40, 0, 90, 0, 50, 0)
WAIT
ready = HERE
FOR n = 1 TO 3
  MOVE L, ready + VEC(0, 0, -30 * n)
  count n
NEXT
PRINT n

SUB count(k AS INT)
  DIM twice AS INT
  twice = 2 * k
END SUB
"""


@pytest.fixture
def arm(executor):  # noqa: F811
    a = ArmCore(executor, ArmConfig(queue_size=8, initial_joints_deg=WORK))
    assert a.servo_on().ok
    return a


def test_breakpoints_step_continue_and_variables(arm, executor):  # noqa: F811
    program = compile_source(Source(PROGRAM, "loop.rbl"))
    stops = []     # (line, variable twice or its absence, the arm at rest, n)

    def at_breakpoint():
        executor.step()
        if run.host.state != "at breakpoint" or (stops and stops[-1][4] == run.vm.executed):
            return
        line = run.debugger.line
        try:
            twice = run.variable("twice")[1]
        except KeyError as error:
            twice = str(error.args[0])
        stops.append((line, twice, not arm.device.current and not arm.device.queue,
                      run.variable("n")[1], run.vm.executed))
        if len(stops) == 2:
            run.debugger.step()           # from line 9 into the SUB
        elif len(stops) == 3:
            run.debugger.step()
        elif len(stops) == 4:
            run.debugger.clear([9])
            run.debugger.resume()
        else:
            run.debugger.resume()
    run = ProgramRun(arm, program, step=at_breakpoint, breakpoints=[8, 9])
    assert run.debugger.set([12]) == "no code on line 12"
    result = run.run()
    assert result.status is Status.FINISHED, result.report
    lines = [s[0] for s in stops]
    assert lines[:5] == [8, 9, 13, 15, 8], stops
    assert lines[5:] == [8]                     # 9 cleared: only 8, on the third round
    assert stops[0][1] == "twice is not in scope where the program stands"
    assert stops[3][1] == "I4:0" and stops[3][3] == "I4:1"     # in the SUB: its own variable
    assert all(s[2] for s in stops)              # held once the motions had ended
    assert [line.strip('"') for line in result.output] == ["4"]


def test_progress_names_the_line_and_an_exception_its_source_line(arm, executor):  # noqa: F811
    program = compile_source(Source("DELAY 0.2\nDIM a AS INT\nPRINT 1 \\ a", "zero.rbl"))
    seen = set()

    def step():
        executor.step()
        seen.add(run.progress().line)
    run = ProgramRun(arm, program, step=step)
    result = run.run()
    assert 1 in seen
    assert result.status is Status.EXCEPTION and result.line == 3
    assert result.report.startswith("zero.rbl:3: PRINT 1 \\ a: STROLIC exception: division by")


def test_step_from_the_start_holds_at_the_first_line(arm, executor):  # noqa: F811
    program = compile_source(Source("PRINT 1\nPRINT 2\n", "s.rbl"))
    held = []

    def step():
        executor.step()
        if run.host.state == "at breakpoint" and len(held) < 3 and \
                (not held or held[-1] != run.debugger.line):
            held.append(run.debugger.line)
            run.debugger.step() if len(held) < 2 else run.debugger.resume()
    run = ProgramRun(arm, program, step=step, stepping=True)
    assert run.run().status is Status.FINISHED and held == [1, 2]


CHECKED = """DIM ready AS POSE
SPEED 250
MOVE P, JOINT(0, 40, 0, 90, 0, 50, 0)
WAIT
ready = HERE
ON ERROR CONTINUE
MOVE L, ready + VEC(0, 0, -100)
MOVE L, ready + VEC(0, 0, 2000)
MOVE P, ready + VEC(3000, 0, 0)
"""


def test_check_reports_each_move_and_leaves_the_arm(arm):
    before = arm.get_feedback_pos_joint().values["pos"]
    result = check_program(compile_source(Source(CHECKED, "c.rbl")), arm)
    verdicts = [(m.line, m.command, m.verdict) for m in result.moves]
    assert verdicts == [(3, "ADRIVE", REACHABLE), (7, "ALMOVE", REACHABLE),
                        (8, "ALMOVE", OUTSIDE_SOFT_LIMIT), (9, "AJMOVE", UNREACHABLE)]
    assert result.moves[1].duration > 0.3 and result.moves[2].duration == 0.0
    assert result.total_time >= sum(m.duration for m in result.moves) and not result.cut
    assert not result.success
    assert np.allclose(arm.get_feedback_pos_joint().values["pos"], before)


def test_check_cuts_an_endless_program():
    from acti_motion.executor import MotionExecutor
    from acti_sim.world import World
    world = World()
    try:
        arm = ArmCore(MotionExecutor(world, real_time_factor=0.0),
                      ArmConfig(initial_joints_deg=WORK))
        arm.servo_on()
        endless = "WHILE 1\n  MOVE P, JOINT(0, 40, 0, 90, 0, 50, 0)\n  MOVE P, JOINT(0, 45, 0, " \
                  "80, 0, 50, 0)\nWEND\n"
        result = check_program(compile_source(Source(endless)), arm, budget_s=8.0)
        assert result.cut and "cut after 8 s" in result.message and result.total_time <= 8.1
        assert [m.line for m in result.moves] == [2, 3] and result.moves[0].runs >= 1
        busy = check_program(compile_source(Source("WHILE 1\nWEND\n")), arm, budget_s=8.0,
                             instructions=100_000)
        assert busy.cut and "instructions" in busy.message
    finally:
        world.close()


def test_a_breakpoint_waits_for_a_cancel_too(arm, executor):  # noqa: F811
    program = compile_source(Source("PRINT 1\nPRINT 2\n"))
    run = ProgramRun(arm, program, step=executor.step, breakpoints=[2])

    def step():
        executor.step()
        if run.host.state == "at breakpoint":
            run.cancel()
    run.host.step = step
    result = run.run()
    assert result.status is Status.CANCELED and [o.strip('"') for o in result.output] == ["1"]
