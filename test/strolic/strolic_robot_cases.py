"""Table of cases for the robot-control functions ED00–ED23 on the simulated arm (the coverage
table of the ED area; ``test_strolic_coverage.py`` checks that no function is missing).

A case is ``(program, expected)`` or ``(program, expected, options)``. ``expected`` is the final
stack in the text form (bottom first), an ExceptionKind that must stop the program, or a
``Check`` (a function of the final stack and the arm that asserts). Each case starts with the arm
at ``WORK``, servo on, JSPEED 20 %, SPEED 100 mm/s, SACC 0, hand 1 (the gripper) current.
Options: ``servo`` (False: servo off), ``resume_after`` (s: the operator resumes the arm then).
Flags: 1 invalid value, 2 outside the motion range, 3 another configuration, 4 the arm cannot
move, 5 no such hand (strolic/README.md, robot functions).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from strolic.errors import ExceptionKind as K

TYPE, UNDER = K.TYPE_MISMATCH, K.STACK_UNDERFLOW
OK, INVALID, RANGE, CONFIGURATION, NOT_READY, NO_HAND = (f"I2:{n}" for n in range(6))
WORK = (0.0, 45.0, 0.0, -90.0, 0.0, 45.0, 0.0)   # the control point at (100, 0, 1231.69) mm
FLIPPABLE = "Ar[R8 0 45 0 -90 20 45 20] ADRIVE DROP -1 $WAIT DROP "   # a wrist that can flip within limits
DOWN = "HERE Vec(0 0 -50) DEV"                         # 50 mm below where the arm is
READY = "Ar[R8 0 40 0 90 0 50 0] ADRIVE DROP -1 $WAIT DROP "   # tool down, configuration 2
SOFT_LIMIT = "Ar[R8 0 45 0 -90 0 45 179] ADRIVE"        # J7 past its limit (175°)


@dataclass
class Check:
    """An expectation as a function of the final stack (text form) and the arm."""
    what: str
    test: Callable[[list[str], object], bool]

    def __call__(self, stack: list[str], arm) -> bool:
        return self.test(stack, arm)


def numbers(item: str) -> np.ndarray:
    """The numbers of a Vec(…)/Ar[R4 …] item."""
    inner = item[item.index("(") + 1:-1] if "(" in item else item[item.index(" ") + 1:-1]
    return np.array([float(x.split(":")[-1]) for x in inner.split()])


def flags_then(flags: list[str], test: Callable[[list[str], object], bool], what: str) -> Check:
    return Check(what, lambda s, arm: s[:len(flags)] == flags and test(s[len(flags):], arm))


def position_near(xyz, tol: float = 0.5) -> Callable[[list[str], object], bool]:
    """The last item (HERE LOC) is within tol mm of xyz."""
    return lambda rest, arm: bool(np.linalg.norm(numbers(rest[-1]) - xyz) < tol)


def joints_near(q, tol: float = 0.05) -> Callable[[list[str], object], bool]:
    return lambda rest, arm: bool(np.max(np.abs(numbers(rest[-1]) - q)) < tol)


START = np.array([100.0, 0.0, 1231.685])

CASES: dict[str, list[tuple]] = {
    # ---- ED00–ED05 speeds and accelerations -----------------------------------------------------
    "JSPEED": [("50 JSPEED", [OK]), ("12.5 JSPEED", [OK]), ("150 JSPEED", [INVALID]),
               ("-1 JSPEED", [INVALID]), ('"a" JSPEED', TYPE), ("JSPEED", UNDER),
               ("0 JSPEED Ar[R8 0 45 0 -90 0 45 10] ADRIVE", [OK, NOT_READY])],
    "SPEED": [("200 SPEED", [OK]), ("600 SPEED", [INVALID]), ("-5 SPEED", [INVALID]),
              (f"0 SPEED {DOWN} ALMOVE", [OK, NOT_READY]), ("Vec(1 2 3) SPEED", TYPE)],
    "ACCEL1": [("50 ACCEL1", [OK]), ("0 ACCEL1", [INVALID]), ("101 ACCEL1", [INVALID])],
    "ACCEL2": [("0.5 ACCEL2", [OK]), ("0.01 ACCEL2", [INVALID]), ("20 ACCEL2", [INVALID])],
    "DECEL1": [("100 DECEL1", [OK]), ("-3 DECEL1", [INVALID])],
    "DECEL2": [("1 DECEL2", [OK]), ("11 DECEL2", [INVALID])],
    # ---- ED06–ED0B configuration ----------------------------------------------------------------
    "SCONF": [("5 SCONF GCONF", [OK, "I2:5"]), ("I2:15 SCONF GCONF", [OK, "I2:7"]),
              ("Trn(0 0 0 1 0 0 0 1 0 0 0 1) SCONF", TYPE)],
    "SCONF2": [("3 SCONF2 GCONF2", [OK, "I2:0"])],
    "SCONF3": [("1 30.0 SCONF3 1 GCONF3", [OK, "30.0"]),
               ("1 390.0 SCONF3 1 GCONF3", [OK, "30.0"]),
               ("2 5 SCONF3 2 GCONF3", [OK, "I2:0"])],
    "GCONF": [("GCONF", ["I2:0"]),
              (FLIPPABLE + "GCONF", ["I2:0"])],
    "GCONF2": [("GCONF2", ["I2:0"])],
    "GCONF3": [("1 GCONF3", ["0.0"]), ("9 GCONF3", ["I2:0"])],
    # ---- ED0C–ED10 current state, calibration, pause, delay -----------------------------------
    "HERE": [("HERE LOC", Check("the control point of WORK",
                                lambda s, arm: np.linalg.norm(numbers(s[-1]) - START) < 0.2)),
             ("HERE DESTP", Check("14 pose elements, configuration 0, elbow 0",
                                  lambda s, arm: s[-1] == "I2:14" and s[-3] == "I2:0"))],
    "JHERE": [("JHERE", Check("the WORK joints", lambda s, arm: joints_near(WORK)(s, arm)))],
    "CALIB": [("CALIB JHERE", Check("at home", joints_near((0, 30, 0, -60, 0, 60, 0), 0.1))),
              ("CALIB", K.ROBOT_ERROR, {"servo": False})],
    "PAUSE": [('"change the part" PAUSE', [OK], {"resume_after": 0.2}),
              ("1 PAUSE", TYPE)],
    "DELAY": [("0.25 DELAY", [OK]), ("0 DELAY", [OK]), ("-1 DELAY", [INVALID]),
              ("1e6 DELAY", [INVALID]), ('"1" DELAY', TYPE)],
    # ---- ED11–ED19 motions ------------------------------------------------------------------------
    "AJMOVE": [(f"{DOWN} AJMOVE -1 $WAIT HERE LOC",
                flags_then([OK, OK], position_near(START - [0, 0, 50]), "50 mm down")),
               (f"{DOWN} HERE Vec(0 40 -50) DEV 2 #Pm(120) CONSA AJMOVE -1 $WAIT HERE LOC",
                flags_then([OK, OK], position_near(START + [0, 40, -50]), "through two poses")),
               (FLIPPABLE + "4 SCONF DROP HERE TRN PNT AJMOVE -1 $WAIT DROP GCONF JHERE",
                Check("the wrist flipped (θ6 < 0)", lambda s, arm: s[:2] == [OK, "I2:4"]
                      and numbers(s[-1])[5] < -40)),
               ("HERE Vec(0 0 2000) DEV AJMOVE", [RANGE]),
               ("2 SCONF DROP HERE TRN PNT AJMOVE", [RANGE]),
               ("Pm(1 2 3) AJMOVE", [INVALID]),
               ("0 #Pm(120) CONSA AJMOVE", [INVALID]),
               (f"{DOWN} AJMOVE", [NOT_READY], {"servo": False}),
               ("Vec(1 2 3) AJMOVE", TYPE),
               # a wrong type is the exception (Annex 1 §9), also when the arm cannot move:
               # it was flag 4, and the program went on
               ('"x" AJMOVE', TYPE, {"servo": False})],
    "IJMOVE": [("Trn(0 30 -40 1 0 0 0 1 0 0 0 1) PNT IJMOVE -1 $WAIT HERE LOC",
                flags_then([OK, OK], position_near(START + [0, 30, -40]), "moved by (0 30 -40)")),
               ("Trn(0 0 900 1 0 0 0 1 0 0 0 1) PNT IJMOVE", [RANGE])],
    "ALMOVE": [(f"{DOWN} ALMOVE -1 $WAIT HERE LOC",
                flags_then([OK, OK], position_near(START - [0, 0, 50]), "50 mm down")),
               ("HERE Vec(0 0 2000) DEV ALMOVE", [RANGE]),
               ("4 SCONF DROP HERE TRN PNT ALMOVE", [CONFIGURATION]),
               ("Pm(1.0) ALMOVE", [INVALID]), ('0 SPEED DROP "x" ALMOVE', TYPE)],
    "ILMOVE": [("Trn(20 0 -30 1 0 0 0 1 0 0 0 1) PNT DUP 2 #Pm(120) CONSA ILMOVE -1 $WAIT "
                "HERE LOC", flags_then([OK, OK], position_near(START + [20, 0, -30]),
                                       "each pose relative to the start of the command")),
               ("Trn(0 0 -3000 1 0 0 0 1 0 0 0 1) PNT ILMOVE", [RANGE]),
               (READY + "Trn(0 0 -30 1 0 0 0 1 0 0 0 1) PNT ILMOVE -1 $WAIT HERE DESTP",
                Check("a relative move keeps the arm's configuration (2)",
                      lambda s, arm: s[:2] == [OK, OK] and s[-3] == "I2:2"))],
    "HMOVE": [("Trn(0 0 30 1 0 0 0 1 0 0 0 1) PNT HMOVE -1 $WAIT HERE LOC",
               flags_then([OK, OK], position_near(START + [0, 0, 30]), "30 mm along the tool z")),
              ("Trn(0 0 0 1 0 0 0 -1 0 0 0 -1) 1 2 HANDDEF DROP 2 HANDCHG DROP "
               "Trn(0 0 30 1 0 0 0 1 0 0 0 1) PNT HMOVE -1 $WAIT HERE LOC",
               flags_then([OK, OK], position_near(START - [0, 0, 30]), "hand 2's tool frame")),
              ("Trn(0 0 5000 1 0 0 0 1 0 0 0 1) PNT HMOVE", [RANGE])],
    "CMOVE1": [("1 90.0 HERE Vec(0 50 0) DEV 2 CMOVE1 -1 $WAIT HERE LOC",
                flags_then([OK, OK], position_near(START + [50, 50, 0]), "a quarter circle")),
               ("400 SPEED DROP 2 -90 HERE Vec(0 0 -50) DEV 1 CMOVE1 -1 $WAIT HERE LOC",
                flags_then([OK, OK], position_near(START + [0, 50, -50]), "clockwise in yz")),
               ("4 90 HERE Vec(0 50 0) DEV 2 CMOVE1", [INVALID]),
               ("1 90 HERE Vec(0 50 0) DEV 5 CMOVE1", [INVALID]),
               ("1 90 HERE 2 CMOVE1", [INVALID]),
               ("1 400 HERE Vec(0 50 0) DEV 2 CMOVE1", [INVALID]),
               ("1 90 HERE Vec(0 5000 0) DEV 2 CMOVE1", [RANGE]),
               ("1 90 Vec(0 0 0) 2 CMOVE1", TYPE), ("0 SPEED DROP 1 90 Vec(0 0 0) 2 CMOVE1", TYPE),
               # the operands are checked from the top down: c before the missing a
               ("Vec(0 0 0) 2 CMOVE1", TYPE)],
    "CMOVE3": [("HERE Vec(0 50 -50) DEV HERE Vec(0 100 0) DEV CMOVE3 -1 $WAIT HERE LOC",
                flags_then([OK, OK], position_near(START + [0, 100, 0]), "a half circle")),
               ("HERE Vec(0 50 0) DEV HERE Vec(0 100 0) DEV CMOVE3", [INVALID]),
               ("HERE Vec(0 500 -500) DEV HERE Vec(0 1000 0) DEV CMOVE3", [RANGE]),
               ("HERE 4 SCONF DROP HERE TRN PNT CMOVE3", [CONFIGURATION]),
               ('"a" HERE CMOVE3', TYPE, {"servo": False})],
    "ADRIVE": [("Ar[R8 10 45 0 -90 0 45 0] ADRIVE -1 $WAIT JHERE",
                flags_then([OK, OK], joints_near((10, 45, 0, -90, 0, 45, 0)), "J1 at 10°")),
               ("Ar[I2 0 45 0 -90 0 45] ADRIVE", [INVALID]),
               (SOFT_LIMIT, [RANGE]),
               ('Ar[St(1) "a"] ADRIVE', TYPE), ("0 JSPEED DROP 5 ADRIVE", TYPE)],
    "IDRIVE": [("Ar[R4 5 -5 0 0 0 0 10] IDRIVE -1 $WAIT JHERE",
                flags_then([OK, OK], joints_near((5, 40, 0, -90, 0, 45, 10)), "moved by the deltas")),
               ("Ar[R8 0 0 0 0 0 0 0 0] IDRIVE", [INVALID]),
               ("Ar[R8 0 0 0 0 0 0 180] IDRIVE", [RANGE]),
               ("5 IDRIVE", TYPE)],
    # ---- ED1A–ED1D approach accuracy, completion -------------------------------------------------
    "SACC": [("5 SACC GACC", [OK, "R4:5.0"]), ("-1 SACC", [INVALID]), ("500 SACC", [INVALID])],
    "GACC": [("GACC", ["R4:0.0"])],
    "$WAIT": [("-1 $WAIT", [OK]),
              ("Ar[R8 20 0 0 0 0 0 0] IDRIVE DROP 0 $WAIT 0.1 $WAIT -1 $WAIT", ["I2:1", "I2:1", OK]),
              ("HANDOPEN 0 $WAIT", ["I2:2"]), ('"a" $WAIT', TYPE)],
    "$DONE": [("$DONE Ar[R8 20 0 0 0 0 0 0] IDRIVE DROP $DONE -1 $WAIT DROP $DONE",
               [OK, "I2:1", OK]),
              ("HANDOPEN $DONE", ["I2:2"]),
              ("Ar[R8 0 0 0 0 0 0 5] IDRIVE DROP HANDOPEN $DONE", ["I2:3"])],
    # ---- ED1E–ED23 hands --------------------------------------------------------------------------
    "HANDOPEN": [("HANDCLOSE HANDOPEN -1 $WAIT 16 DIN", [OK, "I2:33"]),
                 # the open and closed bits follow the hand in use (bit 5 stayed off at 70 mm)
                 ("Trn(0 0 0 1 0 0 0 1 0 0 0 1) 70 50 3 2 HANDDEF 2 HANDCHG HANDOPEN -1 $WAIT "
                  "16 DIN HANDCLOSE -1 $WAIT 16 DIN", [OK, OK, OK, "I2:33", OK, "I2:17"]),
                 ("HANDOPEN", K.SERVO_ERROR, {"servo": False})],
    "HANDCLOSE": [("HANDCLOSE -1 $WAIT 16 DIN", [OK, "I2:17"]),
                  ("Trn(0 0 0 1 0 0 0 1 0 0 0 1) 70 50 3 2 HANDDEF 2 HANDCHG HANDCLOSE -1 $WAIT",
                   Check("hand 2 closes to 50 mm", lambda s, arm: s == [OK, OK, OK] and abs(
                       arm.get_feedback_pos_joint().values["pos"][7] - 50.0) < 1.0)),
                  ("HANDCLOSE", K.SERVO_ERROR, {"servo": False})],
    "GRASP": [("20 1 GRASP -1 $WAIT", Check("opening 20 mm", lambda s, arm: s == [OK, OK] and abs(
                  arm.get_feedback_pos_joint().values["pos"][7] - 20.0) < 1.0)),
              ("200 1 GRASP", [INVALID]), ("1 2 2 GRASP", [INVALID]),
              ("0 GRASP", [INVALID]), ("-2 GRASP", [INVALID]), ("20 1 GRASP", [NOT_READY], {"servo": False}),
              ("1 5 GRASP", UNDER), ('"a" 1 GRASP', TYPE, {"servo": False}),
              ('"a" 1 2 GRASP', TYPE), ('"a" 7 GRASP', TYPE)],
    "HANDDEF": [("Trn(0 0 100 1 0 0 0 1 0 0 0 1) 60 10 3 2 HANDDEF 2 HANDREF",
                 [OK, "Trn(0.0 0.0 100.0 1.0 0.0 0.0 0.0 1.0 0.0 0.0 0.0 1.0)", "60", "10",
                  "I2:3"]),
                ("0 2 HANDDEF Trn(0 0 50 1 0 0 0 1 0 0 0 1) 1 2 HANDDEF 2 HANDREF",
                 [OK, OK, "Trn(0.0 0.0 50.0 1.0 0.0 0.0 0.0 1.0 0.0 0.0 0.0 1.0)", "I2:1"]),
                ("1 2 3 4 4 2 HANDDEF", [INVALID]), ("1 1 2 HANDDEF", [INVALID]),
                ("0 0 HANDDEF", [INVALID]), ("Trn(0 0 0 2 0 0 0 1 0 0 0 1) 1 3 HANDDEF", [INVALID]),
                ("Trn(0 0 0 1 0 0 0 1 0 0 0 1) 999 2 3 HANDDEF", [INVALID]),
                ("0 2 HANDDEF 0 3 HANDDEF 0 4 HANDDEF 0 5 HANDDEF 0 6 HANDDEF 0 7 HANDDEF "
                 "0 8 HANDDEF 0 9 HANDDEF", [OK] * 7 + [NO_HAND])],
    "HANDREF": [("1 HANDREF", ["I2:0"]), ("7 HANDREF", ["I2:-1"]), ("1.4 HANDREF", ["I2:0"])],
    "HANDCHG": [("0 2 HANDDEF 2 HANDCHG", [OK, OK]), ("5 HANDCHG", [NO_HAND])],
}

# The exceptions the standard lists per function, as the flags they give here ("flag n").
LISTED_FLAGS: dict[str, tuple[str, ...]] = {
    "JSPEED": (INVALID,), "SPEED": (INVALID,), "ACCEL1": (INVALID,), "ACCEL2": (INVALID,),
    "DECEL1": (INVALID,), "DECEL2": (INVALID,), "DELAY": (INVALID,),
    "AJMOVE": (INVALID, RANGE), "IJMOVE": (RANGE,), "ALMOVE": (INVALID, RANGE),
    "ILMOVE": (RANGE,), "HMOVE": (RANGE,), "CMOVE1": (INVALID, RANGE),
    "CMOVE3": (INVALID, RANGE), "ADRIVE": (RANGE,), "IDRIVE": (RANGE,), "SACC": (INVALID,),
    "GRASP": (INVALID,), "HANDDEF": (INVALID, NO_HAND), "HANDCHG": (NO_HAND,),
}
