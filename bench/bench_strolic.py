"""Instructions per second of the STROLIC VM on loops (figures only, no assertions): the last
one with an interrupt enabled, so its detection procedure runs between every two slices.

    python bench/bench_strolic.py [iterations]
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from strolic.text import assemble  # noqa: E402
from strolic.vm import VM  # noqa: E402

ARITHMETIC_LOOP = """
.name i %1000 .name acc %1001 .name loop %1002
VAR #i #acc #loop DCL
#i I4:0 STORE  #acc I4:0 STORE
#loop FDEF Fn{
top:
  #acc acc i 3 MUL ADD 7 MOD STORE
  #i i INC STORE
  i I4:{n} LT >top BRT
  END
}
loop
"""

CALL_LOOP = """
.name i %1000 .name twice %1001 .name loop %1002
VAR #i #twice #loop DCL
#i I4:0 STORE
#twice FDEF Fn{ DUP ADD END }
#loop FDEF Fn{
top:
  i twice DROP
  #i i INC STORE
  i I4:{n} LT >top BRT
  END
}
loop
"""

# the arithmetic loop with an interrupt enabled whose detection procedure (an input) stays false
POLLED_LOOP = ("5 1 Fn{ 1 DIN 1 AND END } ACTCODE 5 Fn{ END } ACTION 1 ACT\n"
               + ARITHMETIC_LOOP)


def measure(name: str, source: str, iterations: int) -> None:
    program = assemble(source.replace("{n}", str(iterations)))
    vm = VM()
    start = time.perf_counter()
    vm.run(program)
    elapsed = time.perf_counter() - start
    print(f"{name:28s} {vm.executed:10d} instructions in {elapsed:6.3f} s = "
          f"{vm.executed / elapsed:12,.0f} instructions/s")


def main() -> None:
    iterations = int(sys.argv[1]) if len(sys.argv) > 1 else 20_000
    measure("arithmetic/branch loop", ARITHMETIC_LOOP, iterations)
    measure("function-call loop", CALL_LOOP, iterations)
    measure("arithmetic, interrupt polled", POLLED_LOOP, iterations)


if __name__ == "__main__":
    main()
