"""Data codes both ways (§6–§18), the text form, and decoding fuzz."""
from __future__ import annotations

import struct
import tracemalloc

import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

from strolic import opcodes
from strolic.codec import Code, CodeKind, decode, encode
from strolic.codes import (I1, I2, I4, R4, R8, Array, Function, FunctionCode, Num, Pose, Record,
                           Str, TagHead, Trn, UserCode, Vec)
from strolic.errors import ExceptionKind as K, StrolicError
from strolic.literals import format_head, format_value
from strolic.text import assemble, disassemble
from strolic.values import encode_length, encode_value
from strolic.vm import VM

FUZZ = settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])

# (value, bytes) pairs from the digest's worked examples and the tables
EXAMPLES = [
    (Num(I1, 5), "F1 05"), (Num(I2, 300), "F2 01 2C"), (Num(I4, -1), "F4 FF FF FF FF"),
    (Num(R4, 1.0), "F5 3F 80 00 00"), (Num(R8, 1.0), "F6 3F F0 00 00 00 00 00 00"),
    (Array(TagHead(I2), bytes.fromhex("000100020003")), "F9 F1 06 F2 00 01 00 02 00 03"),
    (Str(b"AB"), "FA F1 02 41 42"),
    (Function(bytes.fromhex("F101F102EF00EF5C")), "FD F1 08 F1 01 F1 02 EF 00 EF 5C"),
    (Record(b"\x01\x02"), "FB F1 02 01 02"),
    (Vec((1.0, 2.0, 3.0)), "FF 01 3F800000 40000000 40400000"),
    (Trn((1.0,) + (0.0,) * 11), "FF 02 3F800000" + " 00000000" * 11),
    (Pose((Num(I1, 1), Num(R4, 1.0))), "FF 04 F1 07 F1 01 F5 3F 80 00 00"),
    (Str(b"x" * 200), "FA F2 00 C8" + " 78" * 200),
    (Array(TagHead(0xFA, 2), b"abcd"), "F9 F1 04 FA F1 02 61 62 63 64"),
]


@pytest.mark.parametrize("value, text", EXAMPLES)
def test_data_codes_encode_and_decode(value, text: str) -> None:
    data = bytes.fromhex(text.replace(" ", ""))
    assert encode_value(value) == data
    (code,) = decode(data)
    assert code.kind is CodeKind.DATA and code.value == value and code.size == len(data)


@pytest.mark.parametrize("text, item", [
    ("F0 10 00", UserCode(0x1000)), ("F0 EF 00", FunctionCode(0xEF00)), ("F0 F0", TagHead(0xF0)),
    ("F0 F7", TagHead(0xF7)), ("F0 F2", TagHead(I2)), ("F0 FA F1 03", TagHead(0xFA, 3)),
    ("F0 F9 F1 06 F2", TagHead(0xF9, 6, TagHead(I2))), ("F0 FF 01", TagHead(0xFF01)),
    ("F0 FF 04 F1 10", TagHead(0xFF04, 16)), ("F0 EB 00 12 34", UserCode(0xEB001234)),
])
def test_suppressed_items(text: str, item) -> None:
    (code,) = decode(bytes.fromhex(text.replace(" ", "")))
    assert code.kind is CodeKind.SUPPRESSED and code.value == item


def test_function_codes_user_codes_and_indirect_references() -> None:
    codes = decode(bytes.fromhex("EF00 1000 EAFF EB001234 F71000 ED11"))
    assert [(c.kind, c.value, c.offset) for c in codes] == [
        (CodeKind.CALL, 0xEF00, 0), (CodeKind.CALL, 0x1000, 2), (CodeKind.CALL, 0xEAFF, 4),
        (CodeKind.CALL, 0xEB001234, 6), (CodeKind.INDIRECT, 0x1000, 10), (CodeKind.CALL, 0xED11, 13)]


@pytest.mark.parametrize("text, reason", [
    ("0FFF", "user codes start at 1000"), ("EF8F", "unassigned function"), ("EC00", "unassigned"),
    ("F3", "reserved tag"), ("F8", "reserved tag"), ("FC", "reserved tag"), ("FE", "Mc reserved"),
    ("FF03", "reserved extended tag"), ("FF80", "user extension without format"),
    ("F2 00", "truncated integer"), ("FA F1 05 41", "string shorter than its length"),
    ("FA F2 00 05 4141414141", "127 or less is an I1"), ("FA F1 FF", "negative length"),
    ("FA F4 00000005 4141414141", "127 or less is an I1"), ("FA F2 FF38", "negative length"),
    ("FA F5 00000000", "length must be an integer"), ("FD F1 02 F1 01", "no END"),
    ("FD F1 02 EF 00", "function data must end with END"), ("F7 EF 00", "indirect to a function"),
    ("F7 F1", "indirect without a user code"), ("F5 7F C0 00 00", "NaN"), ("F6 7FF0000000000000", "inf"),
    ("F9 F1 03 F2 000100", "array length not a multiple"), ("F9 F1 00 F0", "array of #"),
    ("FF 04 F1 02 FA 00", "pose elements must be numbers"), ("F0 0F FF", "# of an unused code"),
])
def test_invalid_codes_are_reported(text: str, reason: str) -> None:
    with pytest.raises(StrolicError) as caught:
        decode(bytes.fromhex(text.replace(" ", "")))
    assert caught.value.kind is K.INVALID_CODE, reason
    assert caught.value.offset is not None


@pytest.mark.parametrize("text, says", [
    ("Rd<0>", "pairs of hex digits"), ("Rd<0 1 2>", "pairs of hex digits"),
    ('"\\x"', "one or two hex digits"), ('"\\xZZ"', "one or two hex digits"),
    ('"\ud800"', "lone surrogate"),
])
def test_texts_that_do_not_assemble_are_invalid_code(text: str, says: str) -> None:
    """They escaped as ValueError and UnicodeEncodeError: a run ended as a controller fault."""
    with pytest.raises(StrolicError) as caught:
        assemble(text)
    assert caught.value.kind is K.INVALID_CODE and says in str(caught.value)


@pytest.mark.parametrize("element, bad, at", [
    ("F6", "7FF0000000000000", 9 * 8),             # R8 elements, the tenth +inf
    ("F5", "7FC00000", 9 * 4),                     # R4, NaN
    ("FF01", "3F800000 7FC00000 3F800000", 9 * 12),  # vectors, the tenth's y NaN
])
def test_a_bad_element_deep_in_an_array_is_reported_at_its_offset(element: str, bad: str,
                                                                   at: int) -> None:
    """Flat arrays are checked at once (numpy), nested ones element by element: the same report."""
    good = {"F6": "3FF0000000000000", "F5": "3F800000", "FF01": "3F800000" * 3}[element]
    data = hexed(good * 9 + bad + good * 40)       # over 127 bytes: an I2 length
    head = f"F9 F2 {len(data):04X} {element}"
    with pytest.raises(StrolicError) as caught:
        decode(hexed(head) + data)
    assert caught.value.kind is K.INVALID_CODE
    assert caught.value.offset == len(hexed(head)) + at


def hexed(text: str) -> bytes:
    return bytes.fromhex(text.replace(" ", ""))


# §6.2: a length above 127 is a 2- or 4-byte integer; both are read, the smallest is written
LONG_FORMS = [
    ("FA F4 000000C8" + " 78" * 200, Str(b"x" * 200), TagHead(0xFA, 200, length_tag=I4)),
    ("FB F4 00000080" + " 01" * 128, Record(b"\x01" * 128), TagHead(0xFB, 128, length_tag=I4)),
    ("FF04 F4 00000082" + " F5 3F800000" * 26, Pose((Num(R4, 1.0),) * 26),
     TagHead(0xFF04, 130, length_tag=I4)),
    ("F9 F4 00000100 F2" + " 0007" * 128, Array(TagHead(I2), bytes.fromhex("0007") * 128),
     TagHead(0xF9, 256, TagHead(I2), I4)),
    ("F9 F2 0190 FA F4 000000C8" + " 61" * 400, Array(TagHead(0xFA, 200), b"a" * 400),
     TagHead(0xF9, 400, TagHead(0xFA, 200, length_tag=I4))),
    ("FD F4 00000082" + " F101" * 64 + " EF5C", Function(hexed("F101" * 64 + "EF5C")),
     TagHead(0xFD, 130, length_tag=I4)),
]


@pytest.mark.parametrize("text, value, head", LONG_FORMS)
def test_lengths_above_127_may_be_4_byte_integers(text: str, value, head: TagHead) -> None:
    """Decoded as the same value, re-encoded as read (Code.head), and as the value in the
    smallest form; the text form spells the longer form as a typed length."""
    data = hexed(text)
    (code,) = decode(data)
    assert (code.kind, code.value, code.head, code.size) == (CodeKind.DATA, value, head, len(data))
    assert encode([code]) == data
    assert encode_value(value) != data and decode(encode_value(value))[0].value == value
    assert disassemble(data).startswith(f"={format_head(head)} ")
    assert assemble(disassemble(data)) == data


@pytest.mark.parametrize("text, head", [
    ("F0 FA F4 000000C8", TagHead(0xFA, 200, length_tag=I4)),
    ("F0 F9 F4 00000190 FA F4 000000C8",
     TagHead(0xF9, 400, TagHead(0xFA, 200, length_tag=I4), I4)),
    ("F0 FA F4 00008000", None),                   # 32768 needs the I4: its smallest form
])
def test_suppressed_tags_keep_their_length_form(text: str, head) -> None:
    data = hexed(text)
    (code,) = decode(data)
    assert code.head == head and code.value == (head or code.value).canonical()
    assert encode([code]) == data and assemble(disassemble(data)) == data


def test_a_long_length_form_inside_a_function_keeps_its_branch_offsets() -> None:
    """Branch offsets count bytes: a round trip through the text must keep the datum's size."""
    program = assemble(f'Fn{{ >skip BRA =St(I4:130) "{"s" * 130}" skip: 7 END }} VAR #%1000 DCL '
                       "#%1000 EXCH STORE %1000")
    assert assemble(disassemble(program)) == program
    assert [format_value(v) for v in VM().run(program).stack] == ["7"]


def test_error_offsets_point_into_nested_function_bodies() -> None:
    program = bytes.fromhex("F101 FD F1 04 F3 00 EF 5C")
    with pytest.raises(StrolicError) as caught:
        decode(program)
    assert caught.value.offset == 5


def test_text_form_round_trip_of_a_program_with_everything() -> None:
    text = """
    .name x %1000
    VAR #x DCL #x FDEF Fn{ a: x 1 ADD >a BRT Fn{ END } DROP END }
    I1:5 I2:5 I4:5 R4:1.5 R8:1.5 -3 300 70000 2.5e-3 "A\\"\\\\\\x00\\n" Rd<0102ff>
    Ar[I2 1 2 3] Ar[R4 0.5] Ar[St(2) "ab" "cd"] Ar[Vec Vec(1 2 3)] Ar[Ar(4, I2) Ar[I2 1 2] Ar[I2 3 4]]
    Ar[Rd(1) Rd<01> Rd<02>] Ar[Fn(2) Fn<ef5c>] Vec(1 -2.5 3e10) Trn(1 2 3 4 5 6 7 8 9 10 11 12)
    Pm(1.0 I2:0 R4:0.5) Fn<f101ef5c>
    #I1 #I2 #I4 #R4 #R8 #St(3) #Rd(0) #Fn(2) #Vec #Trn #Pm(9) #Ar(6, I2) ## #Rf
    #ADD #$WAIT #%1000 #%EB001234 @x @%EB001000 %EAFF FPRECD $WAIT AJMOVE
    """
    program = assemble(text)
    assert assemble(disassemble(program)) == program
    assert disassemble(assemble(disassemble(program))) == disassemble(program)


def test_assembler_labels_compute_branch_offsets() -> None:
    program = assemble("Fn{ top: 1 >top BRA >end BRT end: END }")
    body = decode(program)[0].value.body
    assert body == bytes.fromhex("F101 F2FFF9 EF58 F20000 EF5A EF5C")


@pytest.mark.parametrize("text", [
    "FOO", "%0FFF", "%EC00", "I3:5", "I1:300", "Vec(1 2)", "Ar[I2 1.5]", "Ar[St(2) \"abc\"]",
    "Fn{ 1 ", ">nowhere BRA", "Fn{ a: >a }", ".name ADD %1000", "\"\\q\"", "#Ar(2)", "<01>",
    "R4:1e39", "Fn{ 1 }", "#St(I2:5)", "#St(I4:127)", "#St(-1)", "#St(1.5)", "=St(3) 5",
    '=St(3) "ab"', "=I2", "=St(I4:200) #St(200)", 'Ar[St(I4:200) "x"]', '=St(3) "abc"',
    "=I1 5",
])
def test_assembler_rejects_bad_text(text: str) -> None:
    with pytest.raises(StrolicError):
        assemble(text)


def test_a_label_defined_twice_in_one_body_is_refused() -> None:
    """A branch to a label written twice went silently to the second one (the text form's
    labels name one place in a function body)."""
    with pytest.raises(StrolicError, match="label 'a' is defined twice"):
        assemble("Fn{ >a BRA a: 1 a: END }")
    assert assemble("Fn{ a: END } Fn{ a: END }")       # each body has its own labels


# ---- hypothesis: generated programs round-trip; random bytes only raise StrolicError -------------
def numbers():
    return st.one_of(
        st.integers(-128, 127).map(lambda v: Num(I1, v)),
        st.integers(-2**15, 2**15 - 1).map(lambda v: Num(I2, v)),
        st.integers(-2**31, 2**31 - 1).map(lambda v: Num(I4, v)),
        st.floats(width=32, allow_nan=False, allow_infinity=False).map(lambda v: Num(R4, v)),
        st.floats(allow_nan=False, allow_infinity=False).map(lambda v: Num(R8, v)))


f32 = st.floats(width=32, allow_nan=False, allow_infinity=False)
FUNCTION_CODES = [row.code for row in opcodes.TABLE if row.code != 0xEF5C]
user_codes = st.one_of(st.sampled_from([0x1000, 0x1001, 0x1002]), st.integers(0x1000, 0xEAFF),
                       st.integers(0xEB000000, 0xEBFFFFFF))


def data_values(codes):
    return st.one_of(
        numbers(), st.binary(max_size=140).map(Str), st.binary(max_size=8).map(Record),
        st.tuples(f32, f32, f32).map(Vec), st.tuples(*[f32] * 12).map(Trn),
        st.lists(numbers(), max_size=4).map(lambda e: Pose(tuple(e))),
        st.lists(st.integers(-2**15, 2**15 - 1), max_size=5).map(
            lambda v: Array(TagHead(I2), struct.pack(f">{len(v)}h", *v))),
        st.lists(f32, max_size=4).map(lambda v: Array(TagHead(R4), struct.pack(f">{len(v)}f", *v))),
        st.integers(0, 3).flatmap(lambda k: st.lists(st.binary(min_size=k, max_size=k), max_size=3)
                                  .map(lambda v: Array(TagHead(0xFA, k), b"".join(v)))),
        st.lists(st.tuples(f32, f32, f32), max_size=2).map(
            lambda v: Array(TagHead(0xFF01), b"".join(struct.pack(">3f", *x) for x in v))),
        codes.map(lambda body: Function(encode(body + [Code(CodeKind.CALL, 0xEF5C, 0, 0)]))))


def long_forms():
    """Data and #tags whose lengths (128…300) are written as I4 (§6.2), kept in Code.head."""
    return st.integers(128, 300).flatmap(lambda n: st.sampled_from([
        Code(CodeKind.DATA, Str(b"w" * n), 0, 0, TagHead(0xFA, n, length_tag=I4)),
        Code(CodeKind.DATA, Record(bytes(n)), 0, 0, TagHead(0xFB, n, length_tag=I4)),
        Code(CodeKind.SUPPRESSED, TagHead(0xFA, n), 0, 0, TagHead(0xFA, n, length_tag=I4)),
        Code(CodeKind.SUPPRESSED, TagHead(0xF9, 2 * n, TagHead(I2)), 0, 0,
             TagHead(0xF9, 2 * n, TagHead(I2), I4))]))


def program_codes():
    def extend(children):
        return st.lists(st.one_of(
            long_forms(),
            data_values(children).map(lambda v: Code(CodeKind.DATA, v, 0, 0)),
            st.sampled_from(FUNCTION_CODES).map(lambda c: Code(CodeKind.CALL, c, 0, 0)),
            user_codes.map(lambda c: Code(CodeKind.CALL, c, 0, 0)),
            user_codes.map(lambda c: Code(CodeKind.INDIRECT, c, 0, 0)),
            user_codes.map(lambda c: Code(CodeKind.SUPPRESSED, UserCode(c), 0, 0)),
            st.sampled_from([TagHead(I2), TagHead(0xFA, 3), TagHead(0xF9, 4, TagHead(I2)),
                             TagHead(0xF0), TagHead(0xFF01), TagHead(0xFF04, 0)]).map(
                lambda h: Code(CodeKind.SUPPRESSED, h, 0, 0))), max_size=6)
    return st.recursive(st.just([]), extend, max_leaves=12)


@FUZZ
@given(program_codes())
def test_generated_programs_round_trip_through_bytes_and_text(codes) -> None:
    program = encode(codes)
    decoded = decode(program)
    assert encode(decoded) == program
    def parts(some: list[Code]) -> list[tuple]:
        return [(c.kind, c.value, c.head) for c in some]
    assert parts(decoded) == parts(codes)
    assert assemble(disassemble(program)) == program


def check_decoding(data: bytes) -> None:
    """Decoding raises StrolicError or gives codes that re-encode, through text too, to ``data``."""
    try:
        codes = decode(data)
    except StrolicError:
        return
    assert encode(codes) == data
    assert assemble(disassemble(data)) == data


@FUZZ
@given(st.binary(max_size=64))
def test_random_bytes_raise_only_strolic_errors(data: bytes) -> None:
    check_decoding(data)


@FUZZ
@given(st.lists(st.sampled_from([bytes.fromhex(h) for h in (
    "F1", "F2", "F4", "F5", "F6", "F7", "F9", "FA", "FB", "FD", "FF", "F0", "01", "02", "04",
    "10", "EF", "5C", "EB", "00", "FF01", "FF02", "FF04", "EF5C", "1000")]), max_size=30))
def test_tag_shaped_bytes_raise_only_strolic_errors(pieces) -> None:
    check_decoding(b"".join(pieces))


def test_deep_nesting_is_an_invalid_code_not_a_crash() -> None:
    deep_array_head = bytes.fromhex("F0") + bytes.fromhex("F9F100") * 2000 + bytes.fromhex("F2")
    body = bytes.fromhex("EF5C")
    for _ in range(200):
        body = bytes.fromhex("FD") + encode_length(len(body)) + body + bytes.fromhex("EF5C")
    for program in (deep_array_head, body):
        with pytest.raises(StrolicError) as caught:
            decode(program)
        assert caught.value.kind is K.INVALID_CODE and "deeper" in caught.value.detail
    with pytest.raises(StrolicError):
        assemble("Fn{ " * 2000)
    with pytest.raises(StrolicError):
        assemble("#" + "Ar(0, " * 2000)
    with pytest.raises(StrolicError):                 # array literals in array literals
        assemble("Ar[Ar(4, I2) " * 3000)


@pytest.mark.parametrize("value", [Str(bytes(1 << 18)), Array(TagHead(I1), bytes(1 << 18))])
def test_a_long_datum_is_formatted_without_an_object_per_byte(value) -> None:
    """TRACE, OUTPUT and --stack of 16 MiB took gigabytes (a string object per byte)."""
    tracemalloc.start()
    text = format_value(value)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert len(text) > 1 << 19 and peak < 12 * len(text)


def test_an_exception_quotes_at_most_a_thousand_characters_of_the_program() -> None:
    """A 1 MB bad token was echoed whole into the run's result and its log line."""
    with pytest.raises(StrolicError) as caught:
        assemble("1 DROP " + "y" * 100000)
    report = caught.value.report()
    assert len(report) < 1100 and " characters) … " in report
    with pytest.raises(StrolicError) as caught:          # the reason, at the end, is kept
        assemble("I4:" + "9" * 3000)
    assert "does not fit I4" in caught.value.report() and "(30" in caught.value.report()


def _libc_snprintf(template: bytes, value: int) -> bytes:
    """C's own answer: glibc's snprintf with one int argument."""
    import ctypes
    buffer = ctypes.create_string_buffer(256)
    ctypes.CDLL("libc.so.6").snprintf(buffer, 256, template, ctypes.c_int(value))
    return buffer.value


@pytest.mark.parametrize("conversion", ["d", "i", "o", "x", "X"])
def test_encode2_integer_conversions_are_c89s(conversion: str) -> None:
    """Annex 2: 書式指定は,基本的にANSI Cに従う. Python's % gave %.0d of 0 as 0, signed %+x
    and % o, kept the 0 flag with a precision and wrote %#+o of 1 as 0+1 (about 50 of the
    flag combinations differed from C)."""
    from strolic.formatting import c_encode
    flag_sets = ["", "-", "+", " ", "#", "0", "-+", "+0", " 0", "#0", "#-", "+#", "-0", "#+ 0"]
    differ = []
    for flags in flag_sets:
        if conversion in "di" and "#" in flags:
            continue                                        # undefined in C
        for width in ["", "1", "6"]:
            for precision in ["", ".", ".0", ".1", ".4"]:
                for value in [0, 1, 5, 8, 42, 255, 2147483647] + (
                        [-1, -42, -2147483648] if conversion in "di" else []):
                    template = f"%{flags}{width}{precision}{conversion}".encode()
                    got = c_encode(template, [Num(I4, value)])
                    if got != _libc_snprintf(template, value):
                        differ.append((template, value, got, _libc_snprintf(template, value)))
    assert differ == []


@pytest.mark.parametrize("text, says", [
    ("20 JSPEED DROP FOOBAR -1 $WAIT", "'FOOBAR' is no function, name or number"),
    ("Ar[R8 1 2 3 ADRIVE", "is its ] missing?"),
    ("I2:x", "'x' is not a number of that type"),
])
def test_a_word_that_is_no_code_says_what_it_is_not(text: str, says: str) -> None:
    """A misspelt function read "'FOOBAR' is not a number"; an array without its ] "'ADRIVE' is
    not a number of that type"."""
    with pytest.raises(StrolicError) as caught:
        assemble(text)
    assert says in str(caught.value)
