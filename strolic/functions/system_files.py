"""EE16–EE1E: files, by number, through ``Host.open_file`` (files of the program directory, and
communication ports).

Data is written as text: numbers in decimal (reals with a point or an exponent), strings as
their bytes, other data in the text form (``Vec(1.0 2.0 3.0)``); OUTPUT ends an item with a
blank, LOUTPUT with a line feed. INPUT reads the next blank-delimited item and decides its type
from its text. Any failure stops the program (*file input/output error*).
"""
from __future__ import annotations

from typing import TYPE_CHECKING, BinaryIO

from ..codes import DATA_TYPES, I2, TAGS_BY_NAME, Num, Str
from ..errors import ExceptionKind as K, StrolicError, fail
from ..literals import format_number, format_value
from ..process import Process
from .args import pop_count, pop_head, pop_int
from .system_format import decode_text, text_datum

if TYPE_CHECKING:
    from ..vm import VM

MODES = {1: "r", 2: "w", 4: "a"}
EOF_BIT, NOT_OPEN_BIT, ERROR_BIT = 1, 2, 4
BLANKS = b" \t\r\n"
BRACKETS = {ord("("): ord(")"), ord("["): ord("]"), ord("<"): ord(">"), ord("{"): ord("}")}
MAX_LINE = 65536
TAG_WORDS = {name.encode() for name in TAGS_BY_NAME}


def file_error(detail: str) -> StrolicError:
    return fail(K.FILE_ERROR, detail)


class OpenFile:
    """A file opened by FOPEN: its stream, mode, one byte read ahead, the I/O-error bit."""

    def __init__(self, number: int, stream: BinaryIO, mode: str) -> None:
        self.number = number
        self.stream = stream
        self.mode = mode
        self.ahead = b""
        self.failed = False

    def _io(self, action, *args):
        try:
            return action(*args)
        except (OSError, ValueError) as error:
            self.failed = True
            raise file_error(f"file {self.number}: {error}") from None

    def write(self, data: bytes) -> None:
        if self.mode == "r":
            raise file_error(f"file {self.number} is open for reading")
        self._io(self.stream.write, data)

    def byte(self) -> int | None:
        """The next byte, None at the end of the file."""
        if self.mode != "r":
            raise file_error(f"file {self.number} is open for writing")
        data, self.ahead = self.ahead or self._io(self.stream.read, 1), b""
        return data[0] if data else None

    def at_end(self) -> bool:
        if self.mode != "r":
            return False
        if not self.ahead:
            self.ahead = self._io(self.stream.read, 1) or b""
        return not self.ahead

    def unread(self, byte: int) -> None:
        self.ahead = bytes([byte])

    def close(self) -> None:
        self._io(self.stream.close)


MAX_FILE_NUMBER = 0x7FFF_FFFF     # an I4: a file number beyond is no file's


def _file_number(proc: Process) -> int:
    number = pop_count(proc)
    if not 1 <= number <= MAX_FILE_NUMBER:
        shown = number if abs(number) <= MAX_FILE_NUMBER else f"{float(number):g}"
        raise file_error(f"there is no file {shown} (file numbers are 1 … {MAX_FILE_NUMBER})")
    return number


def _open_file(vm: VM, proc: Process) -> OpenFile:
    number = _file_number(proc)
    file = vm.files.get(number)
    if file is None:
        raise file_error(f"file {number} is not open")
    return file


def _past_end(file: OpenFile) -> StrolicError:
    return file_error(f"read past the end of file {file.number}")


# ---- open, close, status ------------------------------------------------------------------------
def fopen(vm: VM, proc: Process) -> None:
    """FOPEN a b: mode 1 read, 2 write (from the start), 4 append; a number that is already
    open, another mode, or a file that cannot be opened stops the program."""
    mode = MODES.get(pop_count(proc))
    number = _file_number(proc)
    if mode is None:
        raise file_error("open mode must be 1 (read), 2 (write) or 4 (append)")
    if number in vm.files:
        raise file_error(f"file {number} is already open")
    try:
        stream = vm.host.open_file(number, mode)
    except OSError as error:
        raise file_error(f"cannot open file {number}: {error.strerror or error}") from None
    vm.files[number] = OpenFile(number, stream, mode)


def fclose(vm: VM, proc: Process) -> None:
    file = _open_file(vm, proc)
    del vm.files[file.number]
    file.close()


def fstat(vm: VM, proc: Process) -> None:
    """FSTAT a: bit 0 end of file reached (a file open for reading), bit 1 not open, bit 2 an
    access to it failed. A number no file can have is not open."""
    file = vm.files.get(pop_count(proc))
    if file is None:
        proc.push(Num(I2, NOT_OPEN_BIT))
        return
    proc.push(Num(I2, (EOF_BIT if file.at_end() else 0) | (ERROR_BIT if file.failed else 0)))


# ---- writing ------------------------------------------------------------------------------------
def text_of(value) -> bytes:
    """The text OUTPUT writes for a datum."""
    if isinstance(value, Num):
        return format_number(value, typed=False).encode("ascii")
    if isinstance(value, Str):
        return value.data
    if isinstance(value, DATA_TYPES):
        return format_value(value).encode("ascii")
    raise fail(K.TYPE_MISMATCH, "only data can be written to a file")


def writer(end: bytes):
    """OUTPUT (an item and a blank), LOUTPUT (an item and a line feed)."""
    def handler(vm: VM, proc: Process) -> None:
        value = proc.pop()
        file = _open_file(vm, proc)
        text = text_of(value) + end
        vm.claim(len(text))           # a communication port keeps it in memory
        file.write(text)
    return handler


output, loutput = writer(b" "), writer(b"\n")


def putc(vm: VM, proc: Process) -> None:
    """PUTC a b: the low-order 8 bits of b."""
    data = pop_int(proc).value
    _open_file(vm, proc).write(bytes([data & 0xFF]))


# ---- reading ------------------------------------------------------------------------------------
def getc(vm: VM, proc: Process) -> None:
    file = _open_file(vm, proc)
    byte = file.byte()
    if byte is None:
        raise _past_end(file)
    proc.push(Num(I2, byte))


def _item(file: OpenFile) -> bytes:
    """The next blank-delimited item; a quoted string or a datum in the text form (a tag name
    and brackets) may hold blanks."""
    byte = file.byte()
    while byte is not None and byte in BLANKS:
        byte = file.byte()
    if byte is None:
        raise _past_end(file)
    item, closing, quoted = bytearray(), [], False
    while byte is not None and (quoted or closing or byte not in BLANKS):
        item.append(byte)
        if quoted:
            quoted = not (byte == ord('"') and item[-2:-1] != b"\\")
        elif byte == ord('"') and (len(item) == 1 or closing):
            quoted = True
        elif byte in BRACKETS and (closing or bytes(item[:-1]) in TAG_WORDS):  # Vec( Ar[ Rd<
            closing.append(BRACKETS[byte])
        elif closing and byte == closing[-1]:
            closing.pop()
        byte = file.byte()
    if byte is not None:
        file.unread(byte)
    return bytes(item)


def input_(vm: VM, proc: Process) -> None:
    """INPUT a: the next item; its text decides the type (an integer of the smallest type, a
    real R8, a datum in the text form, otherwise the word as a string)."""
    item = _item(_open_file(vm, proc))
    datum = text_datum(item)
    proc.push(datum if isinstance(datum, DATA_TYPES) else Str(item))


def _line(file: OpenFile) -> bytes:
    line = bytearray()
    byte = file.byte()
    if byte is None:
        raise _past_end(file)
    while byte is not None and byte != ord("\n"):
        line.append(byte)
        if len(line) > MAX_LINE:
            raise file_error(f"a line of file {file.number} is longer than {MAX_LINE} bytes")
        byte = file.byte()
    return bytes(line[:-1] if line.endswith(b"\r") else line)


def linput(vm: VM, proc: Process) -> None:
    """LINPUT a #t: one line (without its line feed) converted to type t as DECODE1 does."""
    head = pop_head(proc)
    proc.push(decode_text(_line(_open_file(vm, proc)), head))
