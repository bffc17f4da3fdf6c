"""RoboLine → STROLIC codes. Every construct becomes standard codes of JIS B 8440 (no code of
its own), so the result runs on any STROLIC interpreter:

* variables are user codes (globals declared at the start, a routine's locals in a nesting
  level of its own on each call, so recursion works); taught points are globals set first;
* SUBs and FUNCTIONs are function data (FDEF), called by their user code with the arguments on
  the stack; the main program is one too, since branches act only inside function bodies;
* IF/FOR/WHILE/GOTO are BRF/BRT/BRA to labels, GOSUB/RETURN are BAL/RET, STOP is GRET;
* a robot statement stores its error flag in the variable ERR; unless ON ERROR CONTINUE, a
  non-zero flag stops the program at that line (it evaluates a user code never declared).

Every code is kept with the line it came from: the source map of `Program`.
"""
from __future__ import annotations

from lark import Token, Tree

from strolic.codes import I2, I4, R8, Function, Num, Str, Vec, make_number

from .builtins import NUMERIC
from .commands import Commands
from .emitter import FIRST_KEY, Body, Encoded, Routine, named, position
from .parser import parse
from .points import Point
from .program import FAIL_CODE, Program, Symbol
from .source import Source

DEFAULTS = {"int": Num(I4, 0), "real": Num(R8, 0.0), "string": Str(b""),
            "vector": Vec((0.0, 0.0, 0.0))}


class Compiler(Commands):
    def __init__(self, source: Source, points: dict[str, Point] | None = None) -> None:
        self.source = source
        self.points = points or {}
        self.next_key = FIRST_KEY
        self.globals: dict[str, Symbol] = {}
        self.locals: dict[str, Symbol] = {}
        self.routines: dict[str, Routine] = {}
        self.routine: Routine | None = None
        self.body = Body()
        self.line = 0
        self.stop_on_error = True
        self.serial = 0
        self.spare: list[Symbol] = []
        self._locals_seen: list[dict[str, Symbol]] = []

    # ---- the program --------------------------------------------------------------------------
    def compile(self) -> Program:
        tree = parse(self.source)
        main = [item for item in tree.children if item.data not in ("sub_def", "func_def")]
        for item in tree.children:
            if item.data in ("sub_def", "func_def"):
                self.register(item)
        self.globals["ERR"] = Symbol("ERR", "int", self.new_key(None))
        for point in self.points.values():
            self.globals[point.name.upper()] = Symbol(point.name, point.type,
                                                      self.new_key(None))
        main_nodes = [node for statement in main for node in subtrees(statement)]
        for node in main_nodes:
            if node.data == "dim":
                self.declare_dim(node, self.globals)
        bodies = [(routine, self.routine_body(routine)) for routine in self.routines.values()]
        main_key = self.new_key(None)
        return self.link(bodies, main_key, self.main_body(main, main_nodes))

    def declare_dim(self, dim: Tree, table: dict[str, Symbol]) -> None:
        names, type_name, _ = dim.children[1:-2], dim.children[-2], dim.children[-1]
        type_ = self.type_of(type_name)
        for name in names:
            self.declare(name, type_, table)

    def register(self, item: Tree) -> None:
        name, params = item.children[1], item.children[2]
        result = self.type_of(item.children[3]) if item.data == "func_def" else None
        if name.upper() in self.routines:
            raise self.error(name, f"{name} is defined twice")
        parameters = []
        for param in (params.children if params is not None else []):
            if param is not None:
                parameters.append((param.children[0], self.type_of(param.children[1])))
        self.routines[name.upper()] = Routine(str(name), self.new_key(name), parameters, result,
                                              item)

    def routine_body(self, routine: Routine) -> Encoded:
        self.routine, self.locals, self.body = routine, {}, Body()
        self.stop_on_error = True
        tree = routine.tree
        self.line = position(tree)[0]
        params = [self.declare(name, type_, self.locals) for name, type_ in routine.params]
        block = next(c for c in tree.children if isinstance(c, Tree) and c.data == "block")
        nodes = subtrees(block)
        for node in nodes:
            if node.data == "dim":
                self.declare_dim(node, self.locals)
        self.prepare_hidden(nodes, self.locals)
        symbols = list(self.locals.values())
        self._locals_seen.append({f"{routine.name.upper()}.{name}": symbol
                                  for name, symbol in self.locals.items()})
        self.push(Num(I2, 1))
        self.op("NESTIN", "VAR")
        for symbol in symbols:
            self.suppressed(symbol.key)
        self.op("DCL")
        for symbol in reversed(params):
            self.suppressed(symbol.key)
            self.op("EXCH", "STORE")
        self.set_defaults([s for s in symbols if s not in params])
        self.block(block)
        self.line = tree.children[-1].line     # END SUB / END FUNCTION
        if routine.result is not None:         # the end reached without RETURN
            self.default_value(routine.result)
        self.place(" exit")
        self.op("NESTOUT")
        self.routine, self.locals = None, {}
        return self.finish_body()

    def default_value(self, type_: str) -> None:
        if type_ in DEFAULTS:
            self.push(DEFAULTS[type_])
        else:
            self.evaluate(FAIL_CODE)

    def set_defaults(self, symbols: list[Symbol]) -> None:
        for symbol in symbols:
            if symbol.type in DEFAULTS:
                self.suppressed(symbol.key)
                self.push(DEFAULTS[symbol.type])
                self.op("STORE")

    def main_body(self, statements: list[Tree], nodes: list[Tree]) -> Encoded:
        self.body = Body()
        self.stop_on_error = True
        self.prepare_hidden(nodes, self.globals)
        for statement in statements:
            self.statement(statement)
        self.line = 0
        return self.finish_body()

    def link(self, bodies: list[tuple[Routine, Encoded]], main_key: int,
             main: Encoded) -> Program:
        """The program: declarations, taught points, the routines, the main body and its call."""
        self.body, self.line = Body(), 0
        symbols = list(self.globals.values())
        self.op("VAR")
        for key in [s.key for s in symbols] + [r.key for r in self.routines.values()] + [main_key]:
            self.suppressed(key)
        self.op("DCL")
        self.set_defaults(symbols)
        for point in self.points.values():
            self.suppressed(self.globals[point.name.upper()].key)
            self.push(point.value)
            self.op("STORE")
        nested = []             # where each function datum's body starts, and the body
        for routine, body in bodies + [(None, main)]:
            self.line = position(routine.tree)[0] if routine else 0
            self.suppressed(routine.key if routine else main_key)
            self.op("FDEF")
            self.push(Function(body.code))
            nested.append((len(self.body.code) - len(body.code), body))
        self.line = 0
        self.evaluate(main_key)
        symbols = {name: s for name, s in self.globals.items()}
        for routine_locals in self._locals_seen:
            symbols.update(routine_locals)
        return Program(bytes(self.body.code), self.source, self.source_map(nested), symbols)

    def source_map(self, nested: list[tuple[int, Encoded]]) -> dict[int, int]:
        """Offset of every code → its line: the top-level codes and, inside each function datum,
        the codes of its body."""
        table = dict(zip(self.body.starts, self.body.lines))
        for start, body in nested:
            table.update(zip([start + offset for offset in body.starts], body.lines))
        return table

    # ---- statements ---------------------------------------------------------------------------
    def block(self, block: Tree) -> None:
        for statement in block.children:
            self.statement(statement)

    def statement(self, node: Tree) -> None:
        self.line = position(node)[0] or self.line
        getattr(self, f"s_{node.data}")(node)

    def s_label(self, node: Tree) -> None:
        label = node.children[0]
        self.place(str(label).upper(), label)

    def s_goto(self, node: Tree) -> None:
        self.branch(str(node.children[1]).upper(), "BRA", node.children[1])

    def s_gosub(self, node: Tree) -> None:
        self.branch(str(node.children[1]).upper(), "BAL", node.children[1])

    def s_return_(self, node: Tree) -> None:
        value = node.children[1]
        if value is None:
            self.op("RET")
            return
        if self.routine is None or self.routine.result is None:
            raise self.error(node, "RETURN with a value belongs in a FUNCTION (RETURN alone "
                             "ends a GOSUB)")
        self.convert(self.expr(value), self.routine.result, value)
        self.branch(" exit", "BRA")

    def s_exit_(self, node: Tree) -> None:
        kind = str(node.children[1]).upper()
        if self.routine is None or (kind == "SUB") != (self.routine.result is None):
            raise self.error(node, f"EXIT {kind} outside {named(kind)}")
        if self.routine.result is not None:
            self.default_value(self.routine.result)
        self.branch(" exit", "BRA")

    def s_stop(self, node: Tree) -> None:
        self.op("GRET")

    def s_on_error(self, node: Tree) -> None:
        mode = node.children[-1].upper()
        if mode not in ("STOP", "CONTINUE"):
            raise self.error(node.children[-1], "expected ON ERROR STOP or ON ERROR CONTINUE")
        self.stop_on_error = mode == "STOP"

    def s_dim(self, node: Tree) -> None:
        value = node.children[-1]
        if value is None:
            return
        names = node.children[1:-2]
        if len(names) != 1:
            raise self.error(node, "a DIM with a value declares one name")
        self.store(names[0], value)

    def s_assign(self, node: Tree) -> None:
        self.store(node.children[0], node.children[1])

    def store(self, name: Token, value) -> None:
        symbol = self.variable(name)
        if symbol is None:
            raise self.error(name, f"{name} is not declared (DIM {name} AS …)")
        self.suppressed(symbol.key)
        self.convert(self.expr(value), symbol.type, value)
        self.op("STORE")

    def s_if_block(self, node: Tree) -> None:
        end = self.new_label()
        condition, then, *rest = node.children[1:]
        branches = [(condition, then)] + [(e.children[1], e.children[2]) for e in rest[:-1]]
        otherwise = rest[-1]
        for test, block in branches:
            self.line = position(test)[0]
            skip = self.new_label()
            self.condition(test)
            self.branch(skip, "BRF")
            self.block(block)
            self.branch(end, "BRA")
            self.place(skip)
        if otherwise is not None:
            self.block(otherwise.children[1])
        self.place(end)

    def condition(self, node) -> None:
        type_ = self.expr(node)
        if type_ not in NUMERIC:
            raise self.error(node, f"a condition is a number or comparison, not {named(type_)}")

    def s_while_block(self, node: Tree) -> None:
        _, test, block, wend = node.children
        top, end = self.new_label(), self.new_label()
        self.place(top)
        self.condition(test)
        self.branch(end, "BRF")
        self.block(block)
        self.line = wend.line
        self.branch(top, "BRA")
        self.place(end)

    def s_for_block(self, node: Tree) -> None:
        _, name, start, stop, step, block, next_, next_name = node.children
        symbol = self.variable(name)
        if symbol is None or symbol.type not in ("int", "real"):
            raise self.error(name, f"the FOR variable {name} must be declared INT or REAL")
        if next_name is not None and next_name.upper() != name.upper():
            raise self.error(next_name, f"NEXT {next_name} closes FOR {name}")
        increment = (self.written_number(step, "STEP takes a number written out")
                     if step is not None else 1)
        if increment == 0:
            raise self.error(step, "STEP 0 never ends")
        limit = self.hidden(symbol.type, name)
        self.store(name, start)
        self.suppressed(limit.key)
        self.convert(self.expr(stop), symbol.type, stop)
        self.op("STORE")
        top, end = self.new_label(), self.new_label()
        self.place(top)
        self.evaluate(symbol.key)
        self.evaluate(limit.key)
        self.op("GT" if increment > 0 else "LT")
        self.branch(end, "BRT")
        self.block(block)
        self.line = next_.line
        self.suppressed(symbol.key)
        self.evaluate(symbol.key)
        self.push(make_number(I4, increment) if symbol.type == "int"
                  else Num(R8, float(increment)))
        self.op("ADD", "STORE")
        self.branch(top, "BRA")
        self.place(end)

    def hidden(self, type_: str, node) -> Symbol:
        """A variable of the compiler's own (a FOR loop's limit, HANDREF's count), declared
        with the routine's (or the program's) variables: `prepare_hidden` made them."""
        symbol = self.spare.pop()
        return Symbol(symbol.name, type_, symbol.key, symbol.routine)

    def prepare_hidden(self, nodes: list[Tree], table: dict[str, Symbol]) -> None:
        """One hidden variable for each FOR and each HANDREF among `nodes`."""
        count = sum(1 for node in nodes
                    if node.data == "for_block" or node.data in ("call", "name")
                    and node.children[0].upper() == "HANDREF")
        self.spare = []
        for _ in range(count):
            name = f" hidden{self.serial}"
            self.serial += 1
            symbol = Symbol(name, "int", self.new_key(None),
                            self.routine.name if self.routine else "")
            table[name] = symbol
            self.spare.append(symbol)


def subtrees(tree: Tree) -> list[Tree]:
    """The subtrees of `tree` in the order of lark's `iter_subtrees` (children first), without
    its bookkeeping for shared nodes: a parse tree shares none."""
    queue = [tree]
    for node in queue:
        queue += [child for child in reversed(node.children) if isinstance(child, Tree)]
    queue.reverse()
    return queue


def compile_source(source: Source, points: dict[str, Point] | None = None) -> Program:
    """A program's text (and its taught points) → Program; SourceError when it does not
    compile."""
    return Compiler(source, points).compile()
