"""RoboLine without the arm: every construct compiled to STROLIC and run in the VM prints what
the source says; bad programs and bad taught data give the error at its place; the source map
and the command line."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from acti_motion.programs.run import shown_output
from roboline import Program, Source, SourceError, compile_source, parse_points
from strolic.codec import decode
from strolic.errors import StrolicError
from strolic.host import Host
from strolic.opcodes import BY_CODE
from strolic.vm import VM

ROOT = Path(__file__).resolve().parents[2]


def run(text: str, points: str = "") -> tuple[list[str], Program]:
    """What the program PRINTs (its output lines, unquoted)."""
    program = compile_source(Source(text, "t.rbl"),
                             parse_points(Source(points, "t.pts")) if points else None)
    host = Host()
    VM(host).run(program.code)
    return [line.strip('"') for line in shown_output(host.output)], program


CONSTRUCTS = [
    ("DIM i AS INT\ni = 7 \\ 2 + 7 MOD 4 * 10\nPRINT i", ["33"]),
    ("DIM r AS REAL\nr = 7 / 2 + 2 ^ 3\nPRINT r, -r", ["11.5 -11.5"]),
    ("DIM i AS INT = 3\nDIM r AS REAL = i\nr = r / 2\ni = r\nPRINT i, r", ["1 1.5"]),
    ('DIM s AS STRING = "ro"\ns = s + "bot"\nPRINT s, LEN(s), MID(s, 2, 3)', ["robot 5 obo"]),
    ("DIM w AS VECTOR\nw = VEC(1, 2, 2) * 2 - VEC(0, 0, 1)\nPRINT w, NORM(w), X(w), Y(w), Z(w)",
     ["(2, 4, 3) 5.38516 2 4 3"]),
    ("PRINT 3 * VEC(1, 0, 0) + VEC(0, 4, 0) / 2, DOT(VEC(1,2,3), VEC(1,1,1))",
     ["(3, 2, 0) 6"]),
    ("PRINT CROSS(VEC(1, 0, 0), VEC(0, 1, 0)), ABS(-4), SQRT(16), INT(2.5), REAL(2) / 4",
     ["(0, 0, 1) 4 4 2 0.5"]),
    ("PRINT SIN(PI / 2), COS(0), ATAN2(1, 1) * 4 - PI, RADDEG(PI), DEGRAD(180) - PI, &H10",
     ["1 1 0 180 0 16"]),
    ("PRINT 2 < 3, 3 <= 2, 2 = 2.0, 2 <> 3, 3 > 2, 2 >= 3", ["1 0 1 1 1 0"]),
    ("PRINT 1 AND 0, 1 OR 0, NOT 0, NOT (2 > 1), 2 AND 3", ["0 1 1 0 1"]),
    ("DIM i AS INT = 5\nIF i > 3 THEN\n  PRINT \"big\"\nELSEIF i > 1 THEN\n  PRINT \"mid\"\n"
     "ELSE\n  PRINT \"small\"\nEND IF\nIF i < 0 THEN\n  PRINT \"neg\"\nEND IF", ["big"]),
    ("DIM i AS INT = 2\nIF i > 3 THEN\n  PRINT 1\nELSEIF i > 1 THEN\n  PRINT 2\nELSE\n"
     "  PRINT 3\nEND IF", ["2"]),
    ("DIM i AS INT\nFOR i = 10 TO 1 STEP -4\n  PRINT i\nNEXT i", ["10", "6", "2"]),
    ("DIM x AS REAL\nFOR x = 0 TO 1 STEP 0.5\n  PRINT x\nNEXT", ["0", "0.5", "1"]),
    ("DIM i AS INT\nFOR i = 3 TO 1\n  PRINT i\nNEXT", []),
    ("DIM n AS INT = 1\nWHILE n < 100\n  n = n * 3\nWEND\nPRINT n", ["243"]),
    ("DIM n AS INT\n*top:\nn = n + 1\nIF n < 3 THEN\n  GOTO *top\nEND IF\nPRINT n", ["3"]),
    ("GOSUB *twice\nGOSUB *twice\nPRINT \"end\"\nSTOP\n*twice:\n  PRINT \"sub\"\n  RETURN",
     ["sub", "sub", "end"]),
    ("CALL greet(\"you\", 2)\ngreet \"me\", 1\nSUB greet(who AS STRING, n AS INT)\n"
     "  DIM i AS INT\n  FOR i = 1 TO n\n    PRINT \"hello\", who\n  NEXT\nEND SUB",
     ["hello you", "hello you", "hello me"]),
    ("PRINT fact(10), half(3)\nFUNCTION fact(n AS INT) AS INT\n  IF n <= 1 THEN\n"
     "    RETURN 1\n  END IF\n  RETURN n * fact(n - 1)\nEND FUNCTION\n"
     "FUNCTION half(x AS REAL) AS REAL\n  RETURN x / 2\nEND FUNCTION", ["3628800 1.5"]),
    ("DIM g AS INT = 1\nbump\nbump\nPRINT g\nSUB bump\n  g = g * 10\n  IF g > 50 THEN\n"
     "    EXIT SUB\n  END IF\n  PRINT \"bumped\"\nEND SUB", ["bumped", "100"]),
    ("PRINT \"a\"\nSTOP\nPRINT \"b\"", ["a"]),
    ("PRINT \"x\"\nhalt\nPRINT \"y\"\nSUB halt\n  STOP\nEND SUB", ["x"]),
    ("' a comment\nREM another\nPRINT 1 ' after\nPRINT \"it's\" ' quote in a string", ["1", "it's"]),
    ("DOUT 3, 5\nPRINT DIN(3), DIN(3) + 1\nIOWAIT 3, 4, 1, 0\nPRINT ERR, IOWAIT(3, 2, 1, 0)",
     ["5 6", "0 1"]),
    ("PRINT STR(12) + \"/\" + STR(0.5), CLOCK() >= 0", ["12/0.5 1"]),
    ("DIM q AS POSE\nq = POSE(100, 0, 0, 0, 0, 90)\nPRINT q, LOC(SHIFT(q, VEC(1, 2, 3))), "
     "LOC(TSHIFT(q, VEC(1, 0, 0))), q - VEC(100, 0, 0)", ["(100, 0, 0) (101, 2, 3) (100, 1, 0) "
                                                         "(0, 0, 0)"]),
    ("PRINT LOC(PADD(POSE(1, 2, 3, 0, 0, 0), P)), LOC(PSUB(P, P))", ["(11, 22, 33) (0, 0, 0)"]),
    ("PRINT V, A\nA = A + 1\nPRINT A", ["(1, 2, 3) 0", "1"]),
]
POINTS = "POSE P = 10, 20, 30, 0, 0, 0\nVECTOR V = 1, 2, 3\n"


@pytest.mark.parametrize("text, printed", CONSTRUCTS, ids=[c[0].split("\n")[-1][:40]
                                                           for c in CONSTRUCTS])
def test_construct(text, printed):
    points = POINTS + ("VECTOR A = 0, 0, 0\n" if "A =" in text else "")
    if " A" in text:
        text = text.replace("PRINT V, A\n", "DIM A AS INT\nPRINT V, A\n")
        points = POINTS
    assert run(text, points)[0] == printed


def test_every_code_is_standard_and_mapped_to_its_line():
    text = "DIM i AS INT\nFOR i = 1 TO 2\n  PRINT i\nNEXT\nfoo 3\nSUB foo(k AS INT)\n  PRINT k\nEND SUB"
    program = compile_source(Source(text, "t.rbl"))
    offsets = []

    def walk(codes):
        for code in codes:
            offsets.append(code.offset)
            if code.kind.name == "CALL":
                assert code.value in BY_CODE or 0x1000 <= code.value <= 0xEAFF
            if hasattr(code.value, "body"):
                from strolic.codec import decode_function
                walk(decode_function(code.value))
    walk(decode(program.code))
    assert sorted(program.lines) == sorted(offsets)
    assert program.code_lines == {2, 3, 4, 5, 6, 7, 8}
    print_offsets = [o for o, line in program.lines.items() if line == 7]
    assert program.line_at(max(print_offsets)) == 7


def test_a_runtime_exception_names_the_source_line():
    text = "DIM a, b AS INT\na = 1\nb = a \\ (a - 1)\nPRINT b"
    program = compile_source(Source(text, "div.rbl"))
    with pytest.raises(StrolicError) as caught:
        VM(Host()).run(program.code)
    assert program.line_at(caught.value.offset) == 3
    assert program.explain(caught.value).startswith("div.rbl:3: b = a \\ (a - 1): ")


ERRORS = [
    ("DIM a AS INT\nIF a = THEN\nEND IF", 2, 8, "unexpected 'THEN'; expected one of: '(', "),
    ("DIM a AS INT\na = \"x\"", 2, 5, "an INT expected here, not a STRING"),
    ("x = 1", 1, 1, "x is not declared (DIM x AS …)"),
    ("PRINT y + 1", 1, 7, "y is not declared"),
    ("DIM a AS WHOLE", 1, 10, "WHOLE is no type; expected one of: "),
    ("DIM a AS INT\nDIM a AS REAL", 2, 5, "a is declared twice"),
    ("GOTO *nowhere", 1, 6, "label *NOWHERE is not defined in this routine"),
    ("FLY 3", 1, 1, "FLY is no statement, SUB or robot function"),
    ("MOVE X, HERE", 1, 6, "MOVE takes the interpolation first: P or L or C"),
    ("MOVE L, 3", 1, 9, "MOVE L takes a pose, a PATH, not an INT"),
    ("SPEED", 1, 1, "SPEED takes 1 argument, not 0"),
    ("DIM i AS INT\nFOR i = 1 TO 3 STEP i\nNEXT", 2, 21, "STEP takes a number written out"),
    ("DIM i AS INT\nFOR i = 1 TO 3\nNEXT j", 3, 6, "NEXT j closes FOR i"),
    ("DIM i AS INT\nFOR i = 1 TO 3\nPRINT i", 3, 8, "unexpected the end; expected "),
    ("PRINT \"a\" + 1", 1, 7, "no ADD of a STRING and an INT"),
    ("PRINT HERE < 1", 1, 7, "comparisons are of numbers, not of a POSE and an INT"),
    ("CALL nothing", 1, 6, "CALL takes a SUB"),
    ("RETURN 3", 1, 1, "RETURN with a value belongs in a FUNCTION"),
    ("s 1, 2\nSUB s(a AS INT)\nEND SUB", 1, 1, "s takes 1 argument, not 2"),
    ("PRINT f(1)\nSUB f(a AS INT)\nEND SUB", 1, 7, "the SUB f gives no value"),
    ("PRINT POSE(1, 2, 3, 0, 0, a)", 1, 27, "POSE takes numbers written out"),
    ("PRINT 1 +", 1, 10, "unexpected the end of the line; expected one of: "),
    ("PRINT 1 # 2", 1, 9, "unexpected character '#'"),
    ("EXIT SUB", 1, 1, "EXIT SUB outside a SUB"),
    ("ON ERROR RETRY", 1, 10, "expected ON ERROR STOP or ON ERROR CONTINUE"),
]


@pytest.mark.parametrize("text, line, column, message", ERRORS, ids=[e[3][:40] for e in ERRORS])
def test_error_and_its_place(text, line, column, message):
    with pytest.raises(SourceError) as caught:
        compile_source(Source(text, "bad.rbl"))
    error = caught.value
    assert (error.line, error.column) == (line, column), error.report()
    assert message in error.message, error.report()
    head, shown, caret = error.report().split("\n")
    assert head.startswith(f"bad.rbl:{line}:{column}: error: ")
    assert shown.strip() == text.splitlines()[line - 1].strip()
    assert caret.index("^") - 4 == column - 1


POINT_ERRORS = [
    ("PLACE P = 1, 2, 3", 1, 1, "expected POSE, JOINT or VECTOR"),
    ("POSE P = 1, 2, 3", 1, 10, "a POSE takes 6 to 8 numbers, not 3"),
    ("VECTOR V = 1, x, 3", 1, 15, "'x' is not a number"),
    ("JOINT J = 1\nJOINT J = 2", 2, 7, "J is taught twice (line 1)"),
]


@pytest.mark.parametrize("text, line, column, message", POINT_ERRORS)
def test_taught_data_errors(text, line, column, message):
    with pytest.raises(SourceError) as caught:
        parse_points(Source(text, "bad.pts"))
    assert (caught.value.line, caught.value.column, caught.value.message[:len(message)]) == \
        (line, column, message)


def test_command_line(tmp_path):
    program = tmp_path / "count.rbl"
    program.write_text("DIM i AS INT\nFOR i = 1 TO 3\n  PRINT i + V\nNEXT\n")
    (tmp_path / "count.pts").write_text("VECTOR V = 0, 0, 0 ' unused\n")
    env_python = [sys.executable, "-m", "roboline"]
    assert subprocess.run(env_python + ["check", str(program)], cwd=ROOT,
                          capture_output=True, text=True).returncode == 1   # INT + VECTOR
    program.write_text("DIM i AS INT\nFOR i = 1 TO 3\n  PRINT i, V\nNEXT\n")
    done = subprocess.run(env_python + ["check", str(program)], cwd=ROOT, capture_output=True,
                          text=True)
    assert (done.returncode, done.stderr) == (0, "")
    out = tmp_path / "count.stl"
    subprocess.run(env_python + ["compile", str(program), "-o", str(out)], cwd=ROOT, check=True)
    loaded = Program.load(out)
    host = Host()
    VM(host).run(out.read_bytes())
    assert shown_output(host.output) == ['"1 (0, 0, 0)"', '"2 (0, 0, 0)"', '"3 (0, 0, 0)"']
    assert loaded.code_lines == {2, 3, 4} and loaded.symbol("i").type == "int"
    text_form = tmp_path / "count.sasm"
    subprocess.run(env_python + ["compile", str(program), "-o", str(text_form)], cwd=ROOT,
                   check=True)
    from strolic.text import assemble
    assert assemble(text_form.read_text()) == out.read_bytes()
    bad = subprocess.run(env_python + ["check", str(tmp_path / "none.rbl")], cwd=ROOT,
                         capture_output=True, text=True)
    assert bad.returncode == 2 and "none.rbl" in bad.stderr


@pytest.mark.parametrize("cache_state", ["written then loaded", "corrupt", "unwritable"])
def test_the_parser_cache_never_stands_in_the_way(tmp_path, monkeypatch, cache_state):
    """A new process loads the parser's tables from the user's cache; a damaged cache or one
    that cannot be written only costs the time to build them."""
    import hashlib

    from roboline import parser as parser_module
    grammar = parser_module.GRAMMAR.read_text()
    cached = tmp_path / "roboline" / f"grammar-{hashlib.md5(grammar.encode()).hexdigest()}.lark"
    if cache_state == "corrupt":
        cached.parent.mkdir()
        cached.write_bytes(b"garbage\n")
    if cache_state == "unwritable":
        (tmp_path / "roboline").write_text("a file where the cache directory would be")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    try:
        for _ in range(2):                      # the second time from the cache, if any
            parser_module.parser.cache_clear()
            program = compile_source(Source("DIM i AS INT\ni = 2 * 3\nPRINT i\n"))
            host = Host()
            VM(host).run(program.code)
            assert shown_output(host.output) == ['"6"']
    finally:
        parser_module.parser.cache_clear()
    assert cached.exists() == (cache_state != "unwritable")
