"""The tables of what a name means in RoboLine: types, functions in expressions, and the robot
statements, each row naming the STROLIC codes it compiles to.

Argument kinds: num (any number), real (a number, made a real), pose, poses (a pose or a PATH), vector, joint, string.
Result types: int (I4), real, flag (a small integer: I1/I2, made I4 where it is stored or
computed with), string, pose, vector, joint, path, or None (no value).
"""
from __future__ import annotations

TYPES = {"INT": "int", "INTEGER": "int", "REAL": "real", "STRING": "string", "JOINT": "joint",
         "POSE": "pose", "VECTOR": "vector"}
NUMERIC = {"int", "real", "flag"}

# functions in expressions: name → (argument kinds, codes after the arguments, result)
FUNCTIONS: dict[str, tuple[tuple[str, ...], tuple[str, ...], str]] = {
    "ABS": (("num",), ("ABS",), "same"),
    "SQRT": (("real",), ("SQRT",), "real"),
    "SIN": (("real",), ("SIN",), "real"),
    "COS": (("real",), ("COS",), "real"),
    "TAN": (("real",), ("TAN",), "real"),
    "ATAN": (("real",), ("ATAN",), "real"),
    "ATAN2": (("real", "real"), ("ATAN2",), "real"),
    "EXP": (("real",), ("EXP",), "real"),
    "LN": (("real",), ("LN",), "real"),
    "DEGRAD": (("real",), ("DEGRAD",), "real"),
    "RADDEG": (("real",), ("RADDEG",), "real"),
    "PI": ((), ("PI",), "real"),
    "INT": (("num",), ("INT4",), "int"),
    "REAL": (("num",), ("REAL8",), "real"),
    "LEN": (("string",), ("LNG",), "flag"),
    "MID": (("string", "num", "num"), ("MID",), "string"),
    "LOC": (("pose",), ("LOC",), "vector"),
    "NORM": (("vector",), ("VLEN",), "real"),
    "DOT": (("vector", "vector"), ("VPRODI",), "real"),
    "CROSS": (("vector", "vector"), ("VPRODO",), "vector"),
    "SHIFT": (("pose", "vector"), ("DEV",), "pose"),
    "TSHIFT": (("pose", "vector"), ("DEVH",), "pose"),
    "PADD": (("pose", "pose"), ("PADD",), "pose"),
    "PSUB": (("pose", "pose"), ("PSUB",), "pose"),
    "X": (("vector",), ("DESTV", "DROP", "DROP"), "real"),
    "Y": (("vector",), ("DESTV", "DROP", "EXCH", "DROP"), "real"),
    "Z": (("vector",), ("DESTV", "EXCH", "DROP", "EXCH", "DROP"), "real"),
    "CLOCK": ((), ("CLOCK",), "int"),
    "DIN": (("num",), ("DIN",), "flag"),
    "IOWAIT": (("num", "num", "num", "num"), ("IOWAIT", "EXCH", "DROP"), "flag"),
    "WAIT": (("num",), ("$WAIT",), "flag"),
    "DONE": ((), ("$DONE",), "flag"),
}

# robot-control functions ED00–ED23 by mnemonic: (argument kinds, result); as a statement a
# flag goes into ERR, as a function it is the value (GRASP, HANDDEF, HANDREF: see compiler)
ROBOT: dict[str, tuple[tuple[str, ...], str | None]] = {
    "JSPEED": (("num",), "flag"), "SPEED": (("num",), "flag"),
    "ACCEL1": (("num",), "flag"), "ACCEL2": (("num",), "flag"),
    "DECEL1": (("num",), "flag"), "DECEL2": (("num",), "flag"),
    "SCONF": (("num",), "flag"), "SCONF2": (("num",), "flag"),
    "SCONF3": (("num", "num"), "flag"),
    "GCONF": ((), "flag"), "GCONF2": ((), "flag"), "GCONF3": (("num",), "real"),
    "HERE": ((), "pose"), "JHERE": ((), "joint"), "CALIB": ((), None),
    "PAUSE": (("string",), "flag"), "DELAY": (("num",), "flag"),
    "AJMOVE": (("poses",), "flag"), "IJMOVE": (("poses",), "flag"),
    "ALMOVE": (("poses",), "flag"), "ILMOVE": (("poses",), "flag"),
    "HMOVE": (("poses",), "flag"),
    "CMOVE1": (("num", "num", "pose", "num"), "flag"), "CMOVE3": (("pose", "pose"), "flag"),
    "ADRIVE": (("joint",), "flag"), "IDRIVE": (("joint",), "flag"),
    "SACC": (("num",), "flag"), "GACC": ((), "real"),
    "$WAIT": (("num",), "flag"), "$DONE": ((), "flag"),
    "HANDOPEN": ((), None), "HANDCLOSE": ((), None),
    "HANDCHG": (("num",), "flag"),
}

# friendly statement names for robot functions of one mnemonic
STATEMENT_ALIASES = {"ACCURACY": "SACC", "ACCEL": "ACCEL1", "DECEL": "DECEL1",
                     "ACCELTIME": "ACCEL2", "DECELTIME": "DECEL2", "CONFIG": "SCONF",
                     "CONFIG2": "SCONF2"}

# MOVE/IMOVE/APPROACH mode letter → mnemonic for a pose (a joint position drives the joints)
MOVES = {("MOVE", "P"): "AJMOVE", ("MOVE", "L"): "ALMOVE", ("IMOVE", "P"): "IJMOVE",
         ("IMOVE", "L"): "ILMOVE", ("APPROACH", "P"): "AJMOVE", ("APPROACH", "L"): "ALMOVE"}
DRIVES = {"MOVE": "ADRIVE", "IMOVE": "IDRIVE"}

# how PRINT and STR() show a value (C-style formats of ENCODE2)
FORMATS = {"int": "%d", "flag": "%d", "real": "%g", "string": "%s",
           "vector": "(%g, %g, %g)", "pose": "(%g, %g, %g)"}

POSE_BYTES = 120        # a Pm of this VM's layout: 12 R8, the configuration (I2), the elbow (R8)
