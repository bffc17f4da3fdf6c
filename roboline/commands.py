"""Statements that are a name and arguments: the robot statements (MOVE, APPROACH, HAND …,
every ED function by its mnemonic), I/O, PRINT, CALL and a SUB called by its name."""
from __future__ import annotations

from lark import Tree

from strolic.codes import I4, Num, R8, Str, make_number

from .builtins import DRIVES, MOVES, ROBOT, STATEMENT_ALIASES
from .emitter import named
from .expressions import Expressions
from .points import pose_value
from .program import FAIL_CODE

IDENTITY = pose_value([0, 0, 0, 0, 0, 0])


class Commands(Expressions):
    def s_command(self, node: Tree) -> None:
        name, args = node.children[0], [a for a in node.children[1:] if a is not None]
        upper = name.upper()
        special = getattr(self, f"c_{upper.lower()}", None)
        if special is not None and upper.isalpha():
            special(name, args)
        elif upper in self.routines:
            self.call_routine(self.routines[upper], args, name, statement=True)
        elif upper in STATEMENT_ALIASES or upper in ROBOT:
            self.robot(STATEMENT_ALIASES.get(upper, upper), args, name, statement=True)
        else:
            raise self.error(name, f"{name} is no statement, SUB or robot function")

    def flag_statement(self, emit_call) -> None:
        """A command that gives an error flag: it goes into ERR; unless ON ERROR CONTINUE, a
        non-zero flag stops the program here."""
        err = self.globals["ERR"].key
        self.suppressed(err)
        emit_call()
        self.op("INT4", "STORE")
        if self.stop_on_error:
            ok = self.new_label()
            self.evaluate(err)
            self.branch(ok, "BRF")
            self.evaluate(FAIL_CODE)
            self.place(ok)

    def robot(self, mnemonic: str, args: list, node, statement: bool) -> str | None:
        kinds, result = ROBOT[mnemonic]
        self.check_count(args, len(kinds), node)

        def call() -> None:
            for arg, kind in zip(args, kinds):
                self.argument(arg, kind)
            self.op(mnemonic)
        if statement and result == "flag":
            self.flag_statement(call)
            return None
        call()
        if statement and result is not None:
            self.op("DROP")
        return result

    def mode(self, args: list, node, modes: str) -> str:
        if not args or not (isinstance(args[0], Tree) and args[0].data == "name"
                            and args[0].children[0].upper() in modes):
            raise self.error(args[0] if args else node,
                             f"{node} takes the interpolation first: "
                             + " or ".join(modes) + " (P joint, L linear, C circular)")
        return str(args[0].children[0]).upper()

    def c_move(self, name, args) -> None:
        mode = self.mode(args, name, "PLC")
        if mode == "C":
            self.check_count(args[1:], 2, name)
            self.flag_statement(lambda: (self.argument(args[1], "pose"),
                                         self.argument(args[2], "pose"), self.op("CMOVE3")))
            return
        self.move(name, mode, args[1:])

    def c_imove(self, name, args) -> None:
        self.move(name, self.mode(args, name, "PL"), args[1:])

    def move(self, name, mode: str, args: list) -> None:
        self.check_count(args, 1, name)

        def call() -> None:
            type_ = self.expr(args[0])
            if type_ == "joint" and mode == "P":
                self.op(DRIVES[name.upper()])
            elif type_ in ("pose", "path"):
                self.op(MOVES[(name.upper(), mode)])
            else:
                raise self.error(args[0], f"{name} {mode} takes a pose, a PATH"
                                 + (" or a joint position" if mode == "P" else "")
                                 + f", not {named(type_)}")
        self.flag_statement(call)

    def c_approach(self, name, args) -> None:
        """APPROACH P|L, pose, distance: to the pose moved back along its tool axis."""
        mode = self.mode(args, name, "PL")
        self.check_count(args[1:], 2, name)

        def call() -> None:
            self.argument(args[1], "pose")
            self.tool_offset(args[2])
            self.op("DEVH", MOVES[("APPROACH", mode)])
        self.flag_statement(call)

    def c_depart(self, name, args) -> None:
        """DEPART distance: straight back along the tool axis from where the arm is going."""
        self.check_count(args, 1, name)

        def call() -> None:
            self.push(IDENTITY)
            self.tool_offset(args[0])
            self.op("DEVH", "HMOVE")
        self.flag_statement(call)

    def tool_offset(self, distance) -> None:
        """Vec(0, 0, −distance): back along the tool's approach axis."""
        self.push(Num(R8, 0.0))
        self.push(Num(R8, 0.0))
        self.argument(distance, "num")
        self.push(Num(R8, -1.0))
        self.op("MUL", "CONSV")

    def c_arc(self, name, args) -> None:
        """ARC plane, angle, centre, orientation: CMOVE1."""
        self.robot("CMOVE1", args, name, statement=True)

    def c_hand(self, name, args) -> None:
        if len(args) != 1 or not (isinstance(args[0], Tree) and args[0].data == "name"
                                  and args[0].children[0].upper() in ("OPEN", "CLOSE")):
            raise self.error(args[0] if args else name, "expected HAND OPEN or HAND CLOSE")
        self.op("HAND" + args[0].children[0].upper())

    def c_grasp(self, name, args) -> None:
        self.flag_statement(lambda: self.grasp(args, name))

    def grasp(self, args, node) -> str:
        self.check_count(args, 1, node)
        self.argument(args[0], "num")
        self.push(make_number(I4, 1))
        self.op("GRASP")
        return "flag"

    def c_handdef(self, name, args) -> None:
        self.flag_statement(lambda: self.handdef(args, name))

    def handdef(self, args, node) -> str:
        """HANDDEF number [, tool pose [, open [, close]]]."""
        if not 1 <= len(args) <= 4:
            raise self.error(node, "HANDDEF takes the hand's number, then up to three "
                             "parameters: tool pose, open and close openings (mm)")
        if len(args) > 1:
            self.argument(args[1], "pose")
            self.op("TRN")
        for arg in args[2:]:
            self.argument(arg, "num")
        self.push(make_number(I4, len(args) - 1))
        self.argument(args[0], "num")
        self.op("HANDDEF")
        return "flag"

    def c_elbow(self, name, args) -> None:
        self.check_count(args, 1, name)
        self.flag_statement(lambda: (self.push(make_number(I4, 1)),
                                     self.argument(args[0], "num"), self.op("SCONF3")))

    def c_wait(self, name, args) -> None:
        """WAIT [timeout]: until the program's motions are over (or the time, s, has passed)."""
        if len(args) > 1:
            raise self.error(name, "WAIT takes at most a timeout (s)")
        if args:
            self.argument(args[0], "num")
        else:
            self.push(make_number(I4, -1))
        self.op("$WAIT", "DROP")

    def c_dout(self, name, args) -> None:
        self.check_count(args, 2, name)
        for arg in args:
            self.argument(arg, "num")
        self.op("DOUT")

    def c_iowait(self, name, args) -> None:
        """IOWAIT port, mask, condition, timeout (ms): ERR is 1 when the time ran out."""
        self.check_count(args, 4, name)
        for arg in args:
            self.argument(arg, "num")
        self.op("IOWAIT", "INT4")
        self.suppressed(self.globals["ERR"].key)
        self.op("EXCH", "STORE", "DROP")

    def c_print(self, name, args) -> None:
        if not args:
            self.push(Str(b""))
        for index, arg in enumerate(args):
            if index:
                self.push(Str(b" "))
                self.op("CONC")
            self.to_text(arg)
            if index:
                self.op("CONC")
        self.op("RESULT")

    def c_call(self, name, args) -> None:
        if len(args) != 1 or not (isinstance(args[0], Tree) and args[0].data in ("call", "name")
                                  and args[0].children[0].upper() in self.routines):
            raise self.error(args[0] if args else name, "CALL takes a SUB: CALL name(arguments)")
        target = args[0].children[0]
        self.call_routine(self.routines[target.upper()],
                          [a for a in args[0].children[1:] if a is not None], target,
                          statement=True)
