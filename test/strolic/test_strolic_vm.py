"""The machine itself: exception reports (§4.5), limits, indirect references, the host hook,
the output stream, and scheduling of processes."""
from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

from conftest import PRELUDE, ClockHost, RecordingHost, error_of, execute, stack_of
from strolic.codec import encode
from strolic.codes import Num, I1, I2
from strolic.errors import ExceptionKind as K, StrolicError
from strolic.text import assemble
from strolic import vm as vm_module
from strolic.vm import VM
from test_strolic_codec import program_codes


def test_exception_report_names_function_offset_and_kind() -> None:
    with pytest.raises(StrolicError) as caught:
        VM().run(assemble("1 2 ADD 0 DIV"))
    error = caught.value
    assert (error.kind, error.function, error.offset) == (K.DIVISION_BY_ZERO, "DIV", 8)
    assert error.report() == ("STROLIC exception: division by zero in DIV at byte 8 (0x8): "
                              "DIV by 0")


def test_exception_inside_a_function_reports_the_absolute_offset() -> None:
    program = assemble(".name f %1000 VAR #f DCL #f FDEF Fn{ 1 0 IDIV END } f")
    with pytest.raises(StrolicError) as caught:
        VM().run(program)
    assert caught.value.function == "IDIV (in function %1000)"
    assert program[caught.value.offset:caught.value.offset + 2] == bytes.fromhex("EF06")


def test_execution_stops_at_the_exception() -> None:
    vm = VM(RecordingHost())
    with pytest.raises(StrolicError):
        vm.run(assemble("1 RESULT 1 0 DIV 2 RESULT"))
    assert vm.host.output == [bytes.fromhex("F101")]


def test_instruction_budget_bounds_a_runaway_loop() -> None:
    error = error_of("#f Fn{ top: >top BRA END } STORE f", budget=1000)
    assert error.kind is K.INSTRUCTION_BUDGET


@pytest.mark.parametrize("budget", [1, 2, 3])
def test_a_budget_of_n_runs_exactly_n_instructions(budget: int) -> None:
    """The instruction past the budget is not run (it was, and counted: n + 1)."""
    vm = VM()
    with pytest.raises(StrolicError) as caught:
        vm.run(assemble("1 RESULT 2 RESULT 3 RESULT"), budget=budget)
    assert caught.value.kind is K.INSTRUCTION_BUDGET and vm.executed == budget
    assert len(vm.host.output) == budget // 2          # each RESULT is the 2nd of a pair


def test_data_stack_and_return_stack_overflow() -> None:
    assert error_of("1 2 3 4 5 6", max_stack=5).kind is K.STACK_OVERFLOW
    assert error_of("#f Fn{ f END } STORE f", max_return_depth=50).kind is K.STACK_OVERFLOW


# f calls (one return-stack entry), BALs to s (one more) and s BALs to itself x times.
NESTED_BALS = ("#f Fn{ >s BAL END s: x >done BRF #x x DEC STORE >s BAL done: RET END } STORE "
               "#x %d STORE f x")


def test_the_return_stack_holds_exactly_its_limit_of_bal_entries() -> None:
    """max_return_depth entries fit (the call and 1 + 8 BALs in 10), one more overflows: a
    limit off by one either way fails one of the two."""
    assert stack_of(NESTED_BALS % 8, max_return_depth=10) == ["0"]
    error = error_of(NESTED_BALS % 9, max_return_depth=10)
    assert (error.kind, error.function.split()[0]) == (K.STACK_OVERFLOW, "BAL")


def test_gret_clears_the_return_stack() -> None:
    """After GRET inside a BAL subroutine the input stream goes on (5) and has nothing to
    return to: a RET there is the exception, not a jump to the BAL's left-over entry."""
    gret_in_subroutine = "#g Fn{ >s BAL 2 END s: GRET END } STORE g "
    assert stack_of(gret_in_subroutine + "5") == ["5"]
    assert error_of(gret_in_subroutine + "RET").kind is K.NO_RETURN_DESTINATION


DOUBLINGS = " ".join(["DUP CONC"] * 28)           # 8 bytes → 2 GiB in 28 instructions


@pytest.mark.parametrize("program", [
    f'"AAAAAAAA" {DOUBLINGS}',                                     # one datum too long
    '"AAAAAAAA" ' + " ".join(["DUP CONC"] * 20) + " DUP DUP DUP 4 #St(8388608) CONSA",
    '"%65535d" ' + " ".join(["DUP CONC"] * 8) + ' "%65535d" CONC ' + "1 " * 257
    + "I2:257 ENCODE2",                                            # 257 fields of 65535
])
def test_a_datum_longer_than_the_heap_is_refused_before_it_is_made(program: str) -> None:
    assert error_of(program).kind is K.MEMORY_EXHAUSTED


@pytest.mark.parametrize("step", ['s "x" CONC', "s RESULT", "SYNC", "101 s OUTPUT",
                                  '#s 0 "x" EMBB s'])
def test_data_piled_up_by_a_loop_is_bounded_by_the_memory_limit(step: str) -> None:
    program = (f'.name s %1005 VAR #s DCL #s "{"A" * 1000}" STORE 101 2 FOPEN '
               f"#f Fn{{ top: {step} >top BRA END }} STORE f")
    assert error_of(program, budget=None, memory_limit=100_000).kind is K.MEMORY_EXHAUSTED


@pytest.mark.parametrize("use", ["DESTA", '"#" EXCH 1 ENCODE1', '"%d" EXCH 1 ENCODE2'])
def test_an_array_is_not_expanded_beyond_the_data_stack(use: str) -> None:
    """Its elements are counted first: 16 MiB of I1 would otherwise be 16 M numbers (1 GB)."""
    program = f"1000 #Ar(0, I1) #x ALLOC DROP x {use}"
    assert error_of(program, max_stack=500).kind is K.STACK_OVERFLOW


def test_function_data_made_at_run_time_is_compiled_within_the_limits(monkeypatch) -> None:
    """8 MiB of codes EMBB'd into an Fn area took 1.1 GB to compile."""
    drops = " ".join(["DROP"] * 100)
    assert error_of(f"#f Fn{{ {drops} END }} STORE f",
                    memory_limit=10_000).kind is K.MEMORY_EXHAUSTED
    monkeypatch.setattr(vm_module, "MAX_BODY", 100)
    assert error_of(f"#f Fn{{ {drops} END }} STORE f").kind is K.MEMORY_EXHAUSTED
    assert stack_of("1 #f Fn{ DROP 2 END } STORE f") == ["2"]


def test_recursion_with_a_branch() -> None:
    factorial = ("#f Fn{ DUP 1 GT >rec BRT RET rec: DUP DEC f MUL END } STORE I4:10 f")
    assert stack_of(factorial) == ["3628800"]


@pytest.mark.parametrize("program, expected", [
    ("#y 5 STORE #x #y STORE @x", ["5"]),
    ("#f Fn{ 9 END } STORE #x #f STORE @x", ["9"]),
    ("#y 5 STORE #x I2:4097 STORE @x", ["5"]),
    ("#x 5 STORE @x", K.TYPE_MISMATCH), ("@%2000", K.UNDEFINED_DATA),
])
def test_indirect_reference(program: str, expected) -> None:
    if isinstance(expected, K):
        assert error_of(program).kind is expected
    else:
        assert stack_of(program) == expected


def test_extended_user_code_alias_is_the_same_variable() -> None:
    assert stack_of("#%EB001000 7 STORE x %EB001000") == ["7", "7"]


def test_trace_goes_to_the_console_only_when_on() -> None:
    vm, _ = execute('1 TRACE TRON "a" TRACE Vec(1 2 3) TRACE TROFF 2 TRACE')
    assert vm.host.lines == ['TRACE "a"', "TRACE Vec(1.0 2.0 3.0)"]


def test_sync_and_result_write_the_output_stream() -> None:
    vm, _ = execute("SYNC 300 RESULT Vec(1 2 3) RESULT")
    assert vm.host.output == [bytes.fromhex("EF73"), bytes.fromhex("F2012C"),
                              bytes.fromhex("FF013F8000004000000040400000")]


def test_a_datum_read_with_a_4_byte_length_is_written_in_the_smallest_form() -> None:
    """§6.2: both forms are read; what the machine writes (RESULT) uses the smallest."""
    vm, _ = execute('=St(I4:200) "' + "z" * 200 + '" RESULT')
    assert vm.host.output == [bytes.fromhex("FAF200C8") + b"z" * 200]


def test_robot_functions_go_to_the_host() -> None:
    error = error_of("1 JSPEED")
    assert (error.kind, error.function) == (K.UNDEFINED_DATA, "JSPEED")

    class Robot(RecordingHost):
        def call(self, vm, proc, opcode):
            proc.pop()
            proc.push(Num(I2, 0))       # the error flag of JSPEED

    assert stack_of("50 JSPEED", host=Robot()) == ["I2:0"]


def test_robot_exceptions_raised_by_the_host_stop_the_program_and_the_robot() -> None:
    class Robot(RecordingHost):
        stopped = None

        def call(self, vm, proc, opcode):
            raise StrolicError(K.EMERGENCY_STOP, "emergency stop button")

        def stop(self, error):
            self.stopped = error.kind

    robot = Robot()
    error = error_of("Trn(0 0 0 1 0 0 0 1 0 0 0 1) PNT ALMOVE 1", host=robot)
    assert (error.kind, error.function, robot.stopped) == (K.EMERGENCY_STOP, "ALMOVE",
                                                           K.EMERGENCY_STOP)


def test_tasks_go_to_the_host() -> None:
    class Tasks(RecordingHost):
        def start_task(self, number):
            return 0 if number == 3 else -1

        def task_state(self, number):
            return 1

        def control_task(self, number, action):
            return 0 if action == "suspend" else 1

    assert stack_of("3 TXQT 4 TXQT 3 TDONE 3 TSUSPEND 3 TKILL 3 5 TPRECD", host=Tasks()) == \
        ["I2:0", "I2:-1", "I2:1", "I2:0", "I2:1", "I2:1"]


def test_processes_have_their_own_stacks_and_share_globals() -> None:
    assert stack_of("#f Fn{ 7 7 #x 5 STORE 1 ESIG END } STORE 9 #f 1 FXQT DROP 1 EWAIT x") == \
        ["9", "5"]


def test_smaller_priority_number_runs_first() -> None:
    program = ("#f Fn{ 1 RESULT 1 ESIG END } STORE #g Fn{ 2 RESULT 2 ESIG END } STORE "
               "#g 2 FXQT #f 1 FXQT 2 50 FPREDC 1 10 FPREDC DROP DROP DROP DROP 1 2 2 EWAITA")
    vm, _ = execute(program)
    assert vm.host.output == [bytes.fromhex("F101"), bytes.fromhex("F102")]


def test_ewait_releases_only_one_waiter() -> None:
    program = ("#f Fn{ 1 EWAIT 2 ESIG END } STORE #f 1 FXQT #f 2 FXQT DROP DROP 1 ESIG 2 EWAIT "
               "1 FDONE 2 FDONE")
    assert stack_of(program) == ["I2:0", "I2:2"]


def test_ret_and_gret_in_a_process_end_it() -> None:
    assert stack_of("#f Fn{ 1 ESIG RET END } STORE #f 1 FXQT DROP 1 EWAIT 1 FDONE") == ["I2:0"]
    assert stack_of("#g Fn{ 1 ESIG GRET END } STORE #f Fn{ g END } STORE "
                    "#f 1 FXQT DROP 1 EWAIT 1 FDONE") == ["I2:0"]


def test_init_from_a_process_resets_and_returns_to_the_input_stream() -> None:
    vm, main = execute("#f Fn{ INIT END } STORE 5 #f 1 FXQT DROP 1 EWAIT 6")
    assert [item.value for item in main.stack] == [6]
    assert set(vm.processes) == {0}


def test_deadlock_is_reported_where_the_program_waits() -> None:
    error = error_of("1 EWAIT")
    assert (error.kind, error.function) == (K.DEADLOCK, "EWAIT")


def test_a_function_datum_can_be_started_directly() -> None:
    assert stack_of("Fn{ 1 ESIG END } 4 FXQT DROP 1 EWAIT 4 FDONE") == ["I2:0"]


# ---- executing generated programs never fails with anything but a STROLIC exception ----------
class ImpatientHost(ClockHost):
    """Waits (IOWAIT, TIMER) pass in no time; a minute of them stops the program."""

    def sleep(self, seconds: float) -> None:
        super().sleep(seconds)
        if self.time > 60:
            raise StrolicError(K.DEADLOCK, "waited a minute for an input or a timer")


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(program_codes(), st.integers(0, 3))
def test_random_programs_stop_only_with_strolic_exceptions(codes, declared) -> None:
    prelude = assemble("VAR #%1000 #%1001 #%1002 DCL #%1000 #%1001 STORE")
    try:
        VM(ImpatientHost(), max_stack=1000, max_return_depth=100).run(prelude + encode(codes),
                                                                     budget=5000)
    except StrolicError as error:
        assert error.kind is not K.COMPUTER_ERROR, error.report()


def test_equal_function_bodies_at_different_offsets_branch_correctly() -> None:
    body = "Fn{ 0 >a BRF 1 a: 2 END }"
    assert stack_of(f"#f {body} STORE 5 5 5 #g {body} STORE f g") == ["5", "5", "5", "2", "2"]
    text = "#f Fn{ 1 EXCH IDIV END } STORE 1 2 3 #g Fn{ 1 EXCH IDIV END } STORE 1 f 0 g"
    program = assemble(PRELUDE + text)
    second_idiv = program.rindex(bytes.fromhex("EF06"))
    with pytest.raises(StrolicError) as caught:
        VM().run(program)
    assert caught.value.function == "IDIV (in function %1003)"
    assert caught.value.offset == second_idiv


def test_cyclic_process_runs_every_period_on_the_host_clock() -> None:
    host = ClockHost()
    program = ("#x 0 STORE #f Fn{ #x x INC STORE x RESULT x 3 GEQ >s BRT END s: 2 ESIG END } "
               "STORE #f 1 FXQT DROP 1 100 FCYCLE DROP 2 EWAIT 1 0 FCYCLE x")
    _, main = execute(program, host=host)
    assert [item.value for item in main.stack] == [2, 3]     # waiting for its next start
    assert host.output == [bytes([0xF1, n]) for n in (1, 2, 3)]
    assert host.time == pytest.approx(0.2)      # started at 0, then at 0.1 and 0.2


def test_variables_persist_between_runs_of_one_vm() -> None:
    vm = VM()
    vm.run(assemble(".name x %1000 VAR #x DCL #x 41 STORE"))
    assert [item.value for item in vm.run(assemble("%1000 INC")).stack] == [42]


def test_heap_counts_areas_with_their_tags_and_free_gives_them_back() -> None:
    """EF67: ALLOC secures a plus the tag; the heap holds the tagged data of every registration
    (shadowed ones too), DCL takes nothing, FREE and ARELS give the area back."""
    free = "0 #I2 #x ALLOC"
    program = (f"{free} "                              # 1000 free
               "100 #St(0) #y ALLOC "                  # FA F1 64 + 100 bytes = 103
               f"{free} "                              # 897
               "VAR #y DCL #y 5 STORE "                # a new registration holding F1 05
               f"{free} "                              # 895: the shadowed one still counts
               f"VAR #y FREE {free} "                  # 897
               f"#y ARELS {free} "                     # 1000
               "996 #St(0) #y ALLOC "                  # FA F2 03 E4 + 996 = 1000: fits
               f"{free} #y ARELS "                     # 0
               "997 #St(0) #y ALLOC #y ASIZE")          # 1001: one short, nothing secured
    assert stack_of(program, heap_limit=1000) == ["1000", "103", "897", "895", "897", "1000",
                                                  "1000", "0", "-1", "I2:-1"]


@pytest.mark.parametrize("step", ["VAR #y DCL", "n ESIG #n n 1 ADD STORE",
                                  'n s "B" CONC CHOUT #n n 1 ADD STORE'])
def test_registrations_flags_and_channel_data_count_as_data_held(step: str) -> None:
    """DCL in a loop grew to 1.1 GB, flags of new numbers without end, and data left in
    channels to 2.9 GB, with nothing counted against the memory limit."""
    program = (f'.name s %1005 .name y %1006 .name n %1007 VAR #s #n DCL #s "{"A" * 1000}" STORE '
               f"#n I4:1 STORE #f Fn{{ top: {step} >top BRA END }} STORE f")
    assert error_of(program, budget=None, memory_limit=1_000_000).kind is K.MEMORY_EXHAUSTED


@pytest.mark.parametrize("program, code", [
    ("#x Rd<7ff0000000000000> STORE #x 0 #R8 EXTB", "EF54"),   # EXTB: the bytes are no R8
    ("#x 1.0 STORE #x 0 Rd<7ff0000000000000> EMBB x", "1000"),  # x read after the write
    ("#x Ar[R8 1.0] STORE #x 0 Rd<7ff0000000000000> EMBB #x 0 EXTE", "EF56"),
])
def test_data_that_is_no_number_at_run_time_is_reported_where_it_is_read(program: str,
                                                                         code: str) -> None:
    """§4.5: the report names the code where the program stopped. Bytes read as a real at run
    time (EXTB, EXTE, a variable rebuilt after EMBB) that are no number (Reference 2: no NaN,
    no ∞) were reported at byte 0, the offset inside the datum, not in the program."""
    program_bytes = assemble(PRELUDE + program)
    with pytest.raises(StrolicError) as caught:
        VM(RecordingHost()).run(program_bytes)
    assert caught.value.kind is K.INVALID_CODE
    offset = caught.value.offset
    assert program_bytes[offset:offset + 2] == bytes.fromhex(code), caught.value.report()


@pytest.mark.parametrize("program, expected", [
    ("0 FKILL 5", ["I2:1", "5"]),                   # 1: process 0 is not executing
    ("#f Fn{ 0 FKILL END } STORE #f 1 FXQT DROP 2 1 1 5 IOWAIT DROP DROP 5", ["5"]),
    ("0 FSUSPEND 5", ["I2:1", "5"]),
    ("#f Fn{ 0 FSUSPEND END } STORE #f 1 FXQT DROP 2 1 1 5 IOWAIT DROP DROP 5", ["5"]),
    ("0 FRESUME", ["I2:1"]), ("0 FDONE", ["I2:0"]), ("0 5 FPRECD", ["I2:0"]),
    ("0 10 FCYCLE", ["I2:0"]),
])
def test_the_program_is_no_process_number(program: str, expected: list[str]) -> None:
    """EF76 FXQT: process numbers are positive integers (0 and below are refused, −2). The
    program itself has none: FKILL 0 ended the program as if it had ended normally (its
    stack kept, the rest not run), FSUSPEND 0 made every process wait (deadlock), FCYCLE 0
    restarted the program. Functions EF78–EF82 treat 0 as a number no process has."""
    assert stack_of(program) == expected


@pytest.mark.parametrize("program", [
    '#g "Fn{ 1 0 DIV END }" #Fn(0) DECODE1 STORE 1 2 g',             # a body read from text
    "2 #Fn(0) #g ALLOC DROP g",                       # an Fn area of zero bytes: invalid code
    '#f Fn{ 7 g END } STORE #g "Fn{ 1 0 DIV END }" #Fn(0) DECODE1 STORE f',   # called by f
])
def test_an_exception_in_a_function_made_at_run_time_is_located_where_it_was_called(
        program: str) -> None:
    """§4.5: the report names the code where the program stopped. A function made at run
    time (DECODE1, an Fn area) has no bytes in the program; its offsets inside its own body
    (and those of the throwaway text DECODE1 read) were reported as program offsets."""
    program_bytes = assemble(PRELUDE + program)
    with pytest.raises(StrolicError) as caught:
        VM(RecordingHost()).run(program_bytes)
    offset = caught.value.offset
    assert program_bytes[offset:offset + 2] == bytes.fromhex("1003"), caught.value.report()


def test_nestout_at_the_outermost_level_is_an_exception_that_keeps_the_globals() -> None:
    """EF5E leaves NESTOUT without a saved level open: here an exception, and the program's
    global space (where x was stored) is not the one dropped."""
    vm = VM()
    with pytest.raises(StrolicError) as caught:
        vm.run(assemble(PRELUDE + "#x 5 STORE NESTOUT"))
    assert caught.value.kind is K.COMPUTER_ERROR and "outermost" in str(caught.value)
    assert vm.main.scopes == [vm.globals]
    assert vm.globals.table[0x1000][-1].value() == Num(I1, 5)
