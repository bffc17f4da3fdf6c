"""RoboLine on the simulated arm (ROS-free): every robot statement and function moves the arm or
answers as the source says; a refused command stops the program at its line; one program
written in both forms (RoboLine and the STROLIC text form) moves the arm the same way."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from acti_motion.arm.core import ArmConfig, ArmCore
from acti_motion.executor import MotionExecutor
from acti_motion.programs.run import ProgramRun, Status
from acti_sim.world import World
from roboline import Source, compile_source, parse_points
from sim_fixtures import executor  # noqa: F401
from strolic.codec import decode, decode_function
from strolic.opcodes import BY_CODE
WORK = (0.0, 45.0, 0.0, -90.0, 0.0, 45.0, 0.0)   # as the STROLIC robot cases start

ROOT = Path(__file__).resolve().parents[2]
READY = "MOVE P, JOINT(0, 40, 0, 90, 0, 50, 0)\nWAIT\nready = HERE\n"
POINTS = "POSE HOME = 663.5, 0, 463.3, 0, 180, 0, 2, 180\nJOINT BENT = 0, 30, 0, 80, 0, 60, 0\n"


@pytest.fixture
def arm(executor):  # noqa: F811
    a = ArmCore(executor, ArmConfig(queue_size=8, initial_joints_deg=WORK))
    assert a.servo_on().ok
    return a


def run(arm, executor, text, points=POINTS, hook=None):  # noqa: F811
    program = compile_source(Source("DIM ready AS POSE\n" + text, "r.rbl"),
                             parse_points(Source(points, "r.pts")))

    def step():
        executor.step()
        if hook is not None:
            hook()
    result = ProgramRun(arm, program.code, step=step).run()
    return result, program, [line.strip('"') for line in result.output]


def tcp_mm(arm) -> np.ndarray:
    return arm.tool_pose(arm.device.queued_end.joints)[:3, 3] * 1000.0


def numbers(line: str) -> np.ndarray:
    return np.array([float(x) for x in line.replace("(", " ").replace(")", " ")
                     .replace(",", " ").split()])


MOTIONS = [
    # program, what it prints (numbers, compared to 0.5), ERR at the end
    (READY + "MOVE L, ready + VEC(0, 0, -100)\nWAIT\nPRINT LOC(HERE) - LOC(ready)", [0, 0, -100]),
    (READY + "MOVE P, ready + VEC(50, 50, -50)\nWAIT\nPRINT LOC(HERE) - LOC(ready)", [50, 50, -50]),
    (READY + "MOVE L, PATH(ready + VEC(0, 50, 0), ready + VEC(0, 50, -50))\nWAIT\n"
     "PRINT LOC(HERE) - LOC(ready)", [0, 50, -50]),
    (READY + "IMOVE L, POSE(0, 0, -80, 0, 0, 0)\nIMOVE P, POSE(30, 0, 0, 0, 0, 0)\nWAIT\n"
     "PRINT LOC(HERE) - LOC(ready)", [30, 0, -80]),
    (READY + "APPROACH L, ready + VEC(0, 0, -150), 50\nWAIT\nPRINT LOC(HERE) - LOC(ready)\n"
     "DEPART 40\nWAIT\nPRINT LOC(HERE) - LOC(ready)", [0, 0, -100, 0, 0, -60]),
    (READY + "HMOVE POSE(0, 0, 60, 0, 0, 0)\nWAIT\nPRINT LOC(HERE) - LOC(ready)", [0, 0, -60]),
    (READY + "MOVE C, ready + VEC(50, 50, 0), ready + VEC(100, 0, 0)\nWAIT\n"
     "PRINT LOC(HERE) - LOC(ready)", [100, 0, 0]),
    (READY + "ARC 1, 180, ready + VEC(50, 0, 0), 2\nWAIT\nPRINT LOC(HERE) - LOC(ready)",
     [100, 0, 0]),
    ("MOVE P, BENT\nIMOVE P, JOINT(0, 10, 0, 10, 0, -10, 0)\nWAIT\nPRINT X(VEC(1,0,0))\n"
     "DIM j AS JOINT\nj = JHERE\n", [1]),
    ("MOVE P, HOME\nWAIT\nPRINT LOC(HERE) - LOC(HOME), GCONF", [0, 0, 0, 0]),
    ("SPEED 300\nJSPEED 80\nACCEL 50\nDECEL 50\nACCELTIME 0.5\nDECELTIME 0.5\nACCURACY 10\n"
     "CONFIG 2\nCONFIG2 0\nELBOW 15\nPRINT GACC, GCONF, GCONF2(), GCONF3(1), ERR", [10, 2, 0, 15, 0]),
    ("SCONF3 1, 20\nSACC 5\nJSPEED 30\nSPEED 100\nACCEL1 100\nDECEL1 100\nACCEL2 1\nDECEL2 1\n"
     "SCONF 0\nSCONF2 0\nPRINT GCONF3(1), GACC()", [20, 5]),
    ("CALIB\nPRINT NORM(LOC(HERE) - LOC(HERE))", [0]),
    ("DIM t AS INT\nt = CLOCK\nDELAY 0.5\nPRINT (CLOCK - t) >= 500", [1]),
    ("MOVE P, BENT\nPRINT WAIT(0) > 0, DONE() > 0\nWAIT\nPRINT DONE()", [1, 1, 0]),
    ("MOVE P, BENT\nWAIT 0.05\nPRINT DONE() > 0\nWAIT", [1]),
    ("HAND CLOSE\nWAIT\nPRINT DIN(16) AND 16\nHAND OPEN\nWAIT\nPRINT DIN(16) AND 32\n"
     "GRASP 30\nWAIT\nPRINT ERR, GRASP(20)", [1, 1, 0, 0]),
    ("HANDDEF 2, POSE(0, 0, 100, 0, 0, 0), 60, 10\nPRINT ERR, HANDREF(2), HANDREF(3)\n"
     "DIM before AS POSE = HERE\nHANDCHG 2\nPRINT NORM(LOC(HERE) - LOC(before))\nHANDCHG 1\n"
     "PRINT HANDDEF(3), HANDCHG(3)", [0, 3, -1, 100, 0, 0]),
    ("ON ERROR CONTINUE\nHANDCHG 9\nPRINT ERR\nSPEED 900\nPRINT ERR\nON ERROR STOP\nPRINT "
     "AJMOVE(HERE), ALMOVE(HERE), IJMOVE(POSE(0,0,0,0,0,0)), ILMOVE(POSE(0,0,0,0,0,0)), "
     "HMOVE(POSE(0,0,0,0,0,0)), ADRIVE(BENT), IDRIVE(JOINT(0,0,0,0,0,0,0))", [5, 1, 0, 0, 0, 0, 0, 0, 0]),
    ("PRINT CMOVE3(SHIFT(HERE, VEC(0, 20, -20)), SHIFT(HERE, VEC(0, 40, 0))), "
     "CMOVE1(1, 10, SHIFT(HERE, VEC(0, 10, 0)), 2), SPEED(100), JSPEED(10), DELAY(0)", [0] * 5),
    ("PRINT ACCEL1(50), DECEL1(50), ACCEL2(1), DECEL2(1), SCONF(0), SCONF2(0), SCONF3(1, 0), "
     "SACC(0), PAUSE(\"\") * 0 + 0", None),
]


@pytest.mark.parametrize("text, printed", MOTIONS[:-1], ids=[m[0].split("\n")[-1][:40]
                                                             for m in MOTIONS[:-1]])
def test_motion(arm, executor, text, printed):  # noqa: F811
    result, _, lines = run(arm, executor, text)
    assert result.status is Status.FINISHED, (result.report, result.console)
    got = np.concatenate([numbers(line) for line in lines])
    assert np.allclose(got, printed, atol=0.5), (lines, result.console)


def test_pause_waits_for_resume(arm, executor):  # noqa: F811
    def resume():
        if arm.device.paused:
            assert arm.resume().ok
    result, _, lines = run(arm, executor, MOTIONS[-1][0], hook=resume)
    assert result.status is Status.FINISHED and lines == ["0 0 0 0 0 0 0 0 0"], result.console
    assert "PAUSE: " in result.console


def test_every_robot_function_is_compiled():
    """ED00–ED23: each appears in the compiled programs of the tests above."""
    used = set()

    def walk(codes):
        for code in codes:
            if code.kind.name == "CALL" and code.value in BY_CODE:
                used.add(BY_CODE[code.value].mnemonic)
            if hasattr(code.value, "body"):
                walk(decode_function(code.value))
    for text, _ in MOTIONS:
        program = compile_source(Source("DIM ready AS POSE\n" + text),
                                 parse_points(Source(POINTS)))
        walk(decode(program.code))
    robot = {row.mnemonic for row in BY_CODE.values() if row.code >> 8 == 0xED}
    assert robot - used == set()


def test_a_refused_move_stops_the_program_at_its_line(arm, executor):  # noqa: F811
    result, program, lines = run(arm, executor, READY + "PRINT 1\nMOVE L, ready + VEC(0, 0, 5000)"
                                 "\nPRINT 2")
    assert result.status is Status.EXCEPTION and lines == ["1"]
    assert program.explain(result.error).startswith(
        "r.rbl:6: MOVE L, ready + VEC(0, 0, 5000): the command was refused")
    assert any("ALMOVE: error flag 2" in line for line in result.console)


PICK_AND_PLACE = """' examples/strolic/robot_pick_and_place.sasm written in RoboLine
DIM pick, place AS POSE
JSPEED 50
SPEED 250
MOVE P, JOINT(0, 40, 0, 90, 0, 50, 0)
WAIT
ready = HERE
pick = ready + VEC(100, -150, -250)
place = ready + VEC(100, 150, -250)
HAND OPEN
MOVE L, pick + VEC(0, 0, 100)
MOVE L, pick
WAIT
GRASP 30
WAIT
MOVE L, pick + VEC(0, 0, 100)
MOVE L, place + VEC(0, 0, 100)
MOVE L, place
WAIT
HAND OPEN
WAIT
MOVE L, place + VEC(0, 0, 100)
MOVE L, ready
WAIT
PRINT ERR, NORM(LOC(HERE) - LOC(ready))
"""


def traced(program) -> tuple:
    """Run on an arm of its own from WORK: the result, the joints at every step, the time."""
    world = World()
    try:
        executor = MotionExecutor(world, real_time_factor=0.0)
        arm = ArmCore(executor, ArmConfig(queue_size=8, initial_joints_deg=WORK))
        assert arm.servo_on().ok
        trace = []
        executor.after_step(lambda _: trace.append(arm.get_feedback_pos_joint().values["pos"]))
        result = ProgramRun(arm, program, step=executor.step).run()
        assert result.status is Status.FINISHED, result.report
        return result, np.array(trace), world.time
    finally:
        world.close()


def test_one_program_in_both_forms_moves_the_same():
    sasm_result, sasm_trace, sasm_time = traced(
        (ROOT / "examples/strolic/robot_pick_and_place.sasm").read_text())
    program = compile_source(Source("DIM ready AS POSE\n" + PICK_AND_PLACE))
    result, trace, time = traced(program.code)
    assert sasm_result.stack[0] in ("0", "I2:0") and result.output[0].startswith('"0 ')
    assert abs(time - sasm_time) < 0.05 and abs(len(trace) - len(sasm_trace)) <= 3
    n = min(len(trace), len(sasm_trace))
    assert np.abs(trace[-n:] - sasm_trace[-n:]).max() < 0.05
