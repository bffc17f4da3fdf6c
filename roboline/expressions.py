"""Expressions: codes that leave a value on the stack, with its type checked at compile time
(arithmetic, comparisons, logic, the built-in functions of builtins.FUNCTIONS, the robot
functions as values, calls of FUNCTIONs)."""
from __future__ import annotations

from lark import Tree

from strolic.codes import I4, POSE, R8, Num, Str, TagHead, make_number

from .builtins import FORMATS, FUNCTIONS, NUMERIC, POSE_BYTES, ROBOT
from .emitter import Emitter, Routine, named
from .points import pose_value

COMPARISONS = {"eq": "EQU", "ne": "NEQ", "lt": "LT", "gt": "GT", "le": "LEQ", "ge": "GEQ"}
ARITHMETIC = {"add": "ADD", "sub": "SUB", "mul": "MUL", "div": "DIV", "idiv": "IDIV",
              "mod": "MOD", "pow": "PWR"}
ESCAPES = {"n": "\n", "t": "\t", '"': '"', "\\": "\\", "0": "\0"}


class Expressions(Emitter):
    def expr(self, node) -> str:
        """Codes that leave the value of `node` on the stack; its type."""
        return getattr(self, f"e_{node.data}")(node)

    def convert(self, type_: str, wanted: str, node) -> None:
        if type_ == wanted:
            return
        if wanted == "int" and type_ in ("flag", "real"):
            self.op("INT4")
        elif wanted == "real" and type_ in ("int", "flag"):
            self.op("REAL8")
        else:
            raise self.error(node, f"{named(wanted)} expected here, not {named(type_)}")

    def e_number(self, node: Tree) -> str:
        value = self.number_value(node.children[0])
        if isinstance(value, float):
            self.push(Num(R8, value))
            return "real"
        try:
            self.push(make_number(I4, value))
        except Exception:
            raise self.error(node, f"{value} does not fit an INT (32 bits)") from None
        return "int"

    def e_string(self, node: Tree) -> str:
        body, out, i = str(node.children[0])[1:-1], [], 0
        while i < len(body):
            if body[i] == "\\" and i + 1 < len(body):
                if body[i + 1] not in ESCAPES:
                    raise self.error(node, f"unknown escape \\{body[i + 1]}")
                out.append(ESCAPES[body[i + 1]])
                i += 2
            else:
                out.append(body[i])
                i += 1
        self.push(Str("".join(out).encode()))
        return "string"

    def e_name(self, node: Tree) -> str:
        name = node.children[0]
        symbol = self.variable(name)
        if symbol is not None:
            self.evaluate(symbol.key)
            return symbol.type
        upper = name.upper()
        if upper in self.routines or not (FUNCTIONS.get(upper) or ROBOT.get(upper, "x"))[0]:
            return self.e_call(Tree("call", [name]))     # a function without arguments
        raise self.error(name, f"{name} is not declared (DIM {name} AS …), nor a taught point")

    def e_call(self, node: Tree) -> str:
        name, args = node.children[0], [a for a in node.children[1:] if a is not None]
        upper = name.upper()
        if upper in self.routines:
            result = self.call_routine(self.routines[upper], args, name, statement=False)
            if result is None:
                raise self.error(name, f"the SUB {name} gives no value (a FUNCTION does)")
            return result
        special = getattr(self, f"f_{upper.lower()}", None)
        if special is not None and upper.isalpha():
            return special(name, args)
        if upper in FUNCTIONS:
            kinds, codes, result = FUNCTIONS[upper]
            self.check_count(args, len(kinds), name)
            types = [self.argument(arg, kind) for arg, kind in zip(args, kinds)]
            self.op(*codes)
            return ("int" if types[0] == "flag" else types[0]) if result == "same" else result
        if upper in ROBOT:
            result = self.robot(upper, args, name, statement=False)
            if result is None:
                raise self.error(name, f"{name} gives no value")
            if upper == "GCONF3":
                self.op("REAL8")
            return result
        raise self.error(name, f"{name} is no function")

    def fits(self, type_: str, kind: str, node) -> None:
        ok = {"num": type_ in NUMERIC, "real": type_ in NUMERIC,
              "poses": type_ in ("pose", "path")}.get(kind, type_ == kind)
        if not ok:
            raise self.error(node, f"{named(kind)} expected here, not {named(type_)}")

    def f_vec(self, name, args) -> str:
        self.check_count(args, 3, name)
        for arg in args:
            self.argument(arg, "num")
        self.op("CONSV")
        return "vector"

    def f_joint(self, name, args) -> str:
        if not args:
            raise self.error(name, "JOINT takes the joint values (deg)")
        for arg in args:
            self.convert(self.expr(arg), "real", arg)
        self.push(make_number(I4, len(args)))
        self.suppressed_tag(TagHead(R8))
        self.op("CONSA")
        return "joint"

    def f_path(self, name, args) -> str:
        """PATH(p1, p2, …): a pose sequence, moved through by one command."""
        if not args:
            raise self.error(name, "PATH takes one or more poses")
        for arg in args:
            self.argument(arg, "pose")
        self.push(make_number(I4, len(args)))
        self.suppressed_tag(TagHead(POSE, POSE_BYTES))
        self.op("CONSA")
        return "path"

    def f_pose(self, name, args) -> str:
        """POSE(x, y, z, rx, ry, rz [, config [, elbow]]) of numbers written out."""
        if not 6 <= len(args) <= 8:
            raise self.error(name, "POSE takes x, y, z (mm), rx, ry, rz (deg) [, config "
                             "[, elbow]]")
        self.push(pose_value([self.written_number(a, "POSE takes numbers written out; compute "
                                                    "poses with pose + VEC(…) or SHIFT/TSHIFT")
                              for a in args]))
        return "pose"

    def f_str(self, name, args) -> str:
        self.check_count(args, 1, name)
        self.to_text(args[0])
        return "string"

    def f_grasp(self, name, args) -> str:
        return self.grasp(args, name)

    def f_handdef(self, name, args) -> str:
        return self.handdef(args, name)

    def f_handref(self, name, args) -> str:
        """HANDREF(hand): how many parameters hand was defined with (−1: not defined); the
        parameters themselves are dropped."""
        self.check_count(args, 1, name)
        self.argument(args[0], "num")
        self.op("HANDREF", "DUP")               # b1 … bn n n
        count = self.hidden("int", name)
        self.suppressed(count.key)
        self.op("EXCH", "STORE")                # b1 … bn n, the count kept
        top, end = self.new_label(), self.new_label()
        self.place(top)                         # b1 … bk k: drop bk while k > 0
        self.op("DUP")
        self.push(make_number(I4, 0))
        self.op("GT")
        self.branch(end, "BRF")
        self.op("EXCH", "DROP", "DEC")
        self.branch(top, "BRA")
        self.place(end)
        self.op("DROP")
        self.evaluate(count.key)
        return "flag"

    def binary(self, node: Tree) -> tuple[str, str]:
        left, right = node.children
        a = self.expr(left)
        if a == "flag":
            self.op("INT4")
        b = self.expr(right)
        if b == "flag":
            self.op("INT4")
        return ("int" if a == "flag" else a), ("int" if b == "flag" else b)

    def arithmetic(self, node: Tree) -> str:
        op = node.data
        a, b = self.binary(node)
        if a in ("int", "real") and b in ("int", "real"):
            if op == "div":
                self.op("DIV")
                return "real"
            if op in ("idiv", "mod") and "real" in (a, b):
                raise self.error(node, f"{op.upper()} takes integers")
            self.op(ARITHMETIC[op])
            return "real" if "real" in (a, b) else "int"
        if op == "add" and a == b == "string":
            self.op("CONC")
            return "string"
        if op in ("add", "sub") and a == b == "vector":
            self.op("VADD" if op == "add" else "VSUB")
            return "vector"
        if op in ("add", "sub") and (a, b) == ("pose", "vector"):
            if op == "sub":
                self.push(Num(R8, -1.0))
                self.op("VTIMES")
            self.op("DEV")
            return "pose"
        if op == "mul" and (a, b) in (("vector", "int"), ("vector", "real")):
            self.op("VTIMES")
            return "vector"
        if op == "mul" and (a, b) in (("int", "vector"), ("real", "vector")):
            self.op("EXCH", "VTIMES")
            return "vector"
        if op == "div" and a == "vector" and b in ("int", "real"):
            self.push(Num(R8, 1.0))
            self.op("EXCH", "DIV", "VTIMES")
            return "vector"
        raise self.error(node, f"no {op.upper()} of {named(a)} and {named(b)}")

    e_add = e_sub = e_mul = e_div = e_idiv = e_mod = e_pow = arithmetic

    def comparison(self, node: Tree) -> str:
        left, right = node.children
        a = self.expr(left)
        if a == "real":
            self.op("REAL8")
        b = self.expr(right)
        if b == "real":
            self.op("REAL8")
        if a not in NUMERIC or b not in NUMERIC:
            raise self.error(node, f"comparisons are of numbers, not of {named(a)} and {named(b)}")
        if a == "real" and b != "real":       # EQU: an integer never equals a real
            self.op("REAL8")
        elif b == "real" and a != "real":
            self.op("EXCH", "REAL8", "EXCH")
        self.op(COMPARISONS[node.data])
        return "flag"

    e_eq = e_ne = e_lt = e_gt = e_le = e_ge = comparison

    def logical(self, node: Tree) -> str:
        for child in node.children:
            self.truth(child)
        self.op("AND" if node.data == "and_" else "OR")
        return "flag"

    e_and_ = e_or_ = logical

    def truth(self, node) -> None:
        """A number as a logical value 1/0 (AND and OR work on bits)."""
        type_ = self.expr(node)
        if type_ not in NUMERIC:
            raise self.error(node, f"a logical operand is a number, not {named(type_)}")
        if type_ != "flag" or not (isinstance(node, Tree) and node.data in
                                   (*COMPARISONS, "and_", "or_", "not_")):
            self.push(make_number(I4, 0))
            self.op("NEQ")

    def e_not_(self, node: Tree) -> str:
        self.condition(node.children[0])
        self.op("NOT")
        return "flag"

    def e_neg(self, node: Tree) -> str:
        type_ = self.expr(node.children[0])
        if type_ == "real":             # NEG takes integers only
            self.push(Num(R8, -1.0))
            self.op("MUL")
            return type_
        if type_ in NUMERIC:
            self.op("NEG")
            return "int" if type_ == "flag" else type_
        if type_ == "vector":
            self.push(Num(R8, -1.0))
            self.op("VTIMES")
            return "vector"
        raise self.error(node, f"no minus of {named(type_)}")

    def argument(self, node, kind: str) -> str:
        """An argument of `kind` (num, poses or a type); a flag is made an I4."""
        type_ = self.expr(node)
        self.fits(type_, kind, node)
        if type_ == "flag":
            self.op("INT4")
        if kind == "real" and type_ != "real":   # the math functions take reals only
            self.op("REAL8")
            return "real"
        return type_

    def to_text(self, node) -> None:
        """A value as a string (PRINT, STR): a blank before all but the first of PRINT's."""
        type_ = self.expr(node)
        if type_ == "pose":
            self.op("LOC")
        if type_ == "joint" or type_ == "path":
            raise self.error(node, f"{named(type_)} cannot be shown as text")
        if type_ != "string":
            self.push(Str(FORMATS[type_].encode()))
            self.op("EXCH")
            self.push(make_number(I4, 1))
            self.op("ENCODE2")

    def call_routine(self, routine: Routine, args: list, node, statement: bool) -> str | None:
        self.check_count(args, len(routine.params), node)
        for arg, (param, type_) in zip(args, routine.params):
            self.convert(self.expr(arg), type_, arg)
        self.evaluate(routine.key)
        if statement and routine.result is not None:
            self.op("DROP")
        return routine.result
