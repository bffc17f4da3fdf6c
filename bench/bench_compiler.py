"""RoboLine: the compile time of a 1,000-line program (goal: at most 50 ms), beside the STROLIC
assembler reading the same program's text form (the baseline, measured in the same run); and the
check before motion's wall time against the program's simulated time (figures, no assertions).

    python bench/bench_compiler.py [repeats]
"""
from __future__ import annotations

import statistics
import sys
import time
from pathlib import Path

import lark

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from roboline import Source, compile_source, parse_points  # noqa: E402
from roboline.parser import GRAMMAR, parse, parser  # noqa: E402
from strolic.text import assemble, disassemble  # noqa: E402

BLOCK = """' block {i}
DIM a{i}, b{i} AS INT
DIM p{i} AS POSE
a{i} = {i} * 3 + 1
b{i} = a{i} MOD 7
IF b{i} > 3 THEN
  PRINT "big", b{i}
ELSEIF b{i} = 0 THEN
  b{i} = b{i} + 1
ELSE
  a{i} = a{i} - b{i}
END IF
FOR b{i} = 1 TO 3
  p{i} = HOME + VEC(10 * b{i}, 0, -20)
  MOVE L, p{i}
NEXT
WHILE a{i} > 0
  a{i} = a{i} \\ 2
WEND
CALL show(a{i}, 0.5 * {i})
SPEED 100 + {i} MOD 50
WAIT
"""
SUB = "SUB show(x AS INT, y AS REAL)\n  PRINT x, y\nEND SUB\n"
POINTS = "POSE HOME = 663.5, 0, 463.3, 0, 180, 0, 2, 180\n"


def program(lines: int) -> str:
    block_lines = BLOCK.count("\n")
    return "".join(BLOCK.format(i=i) for i in range(lines // block_lines)) + SUB


def best(fn, repeats: int) -> tuple[float, float, float, float]:
    """Wall time (best, median) and this process's CPU time (best, median), which a loaded
    machine disturbs much less."""
    walls, cpus = [], []
    for _ in range(repeats):
        start, cpu = time.perf_counter(), time.process_time()
        fn()
        cpus.append(time.process_time() - cpu)
        walls.append(time.perf_counter() - start)
    return min(walls), statistics.median(walls), min(cpus), statistics.median(cpus)


def shown(times: tuple[float, float, float, float]) -> str:
    return (f"wall best {1000 * times[0]:6.1f} ms, median {1000 * times[1]:6.1f} ms; "
            f"CPU best {1000 * times[2]:6.1f} ms, median {1000 * times[3]:6.1f} ms")


def compile_time(repeats: int) -> None:
    text = program(1000)
    points = parse_points(Source(POINTS))
    compile_source(Source(text), points)                 # the grammar, loaded once
    compiled = compile_source(Source(text), points)
    text_form = disassemble(compiled.code)
    assert assemble(text_form) == compiled.code
    ours = best(lambda: compile_source(Source(text), points), repeats)
    parsing = best(lambda: parse(Source(text)), repeats)
    baseline = best(lambda: assemble(text_form), repeats)
    print(f"RoboLine, {text.count(chr(10))} lines -> {len(compiled.code)} bytes of STROLIC code")
    print(f"  compile (parse, check, code, source map): {shown(ours)}   (goal <= 50 ms)")
    print(f"    of which parsing (lark LALR):         {shown(parsing)}")
    print(f"  baseline: assemble its text form ({text_form.count(chr(10))} codes):")
    print(f"                                            {shown(baseline)}")
    print(f"  ratio compile / assemble (median): wall {ours[1] / baseline[1]:.2f}, "
          f"CPU {ours[3] / baseline[3]:.2f}")
    built = best(lambda: lark.Lark(GRAMMAR.read_text(), parser="lalr", maybe_placeholders=True),
                 max(3, repeats // 4))
    loaded = best(lambda: (parser.cache_clear(), parser()), max(3, repeats // 4))
    print("  the parser, once a process (a command's or a node's first compile):")
    print(f"    built from the grammar:                {shown(built)}")
    print(f"    loaded from the user's cache:          {shown(loaded)}")


def check_time() -> None:
    from acti_motion.arm.core import ArmConfig, ArmCore
    from acti_motion.executor import MotionExecutor
    from acti_motion.programs.check import check_program
    from acti_sim.world import World
    world = World()
    try:
        arm = ArmCore(MotionExecutor(world, real_time_factor=0.0),
                      ArmConfig(initial_joints_deg=(0.0, 40.0, 0.0, 90.0, 0.0, 50.0, 0.0)))
        arm.servo_on()
        examples = ROOT / "examples" / "programs"
        points = parse_points(Source((examples / "cell.pts").read_text()))
        for name in ("pick_and_place.rbl", "palletising.rbl"):
            compiled = compile_source(Source((examples / name).read_text(), name), points)
            start = time.perf_counter()
            result = check_program(compiled, arm)
            wall = time.perf_counter() - start
            print(f"check {name:20s} {len(result.moves):3d} move lines, simulated "
                  f"{result.total_time:6.2f} s, checked in {wall:6.2f} s wall: "
                  f"{result.total_time / wall:5.2f} × real time")
    finally:
        world.close()


if __name__ == "__main__":
    compile_time(int(sys.argv[1]) if len(sys.argv) > 1 else 20)
    check_time()
