"""Format conversion of Annex 2: BASIC style (ANSI Full BASIC ``PRINT USING`` images) for
ENCODE1, C style (``sprintf``/``sscanf``, with u, l, L, h meaningless and %c an integer) for
ENCODE2 and DECODE2. Pure functions on bytes and numbers; errors are *conversion error*.

The subset of the BASIC image that is implemented is written down in README.md (choice 50).
"""
from __future__ import annotations

import re
from collections import deque
from decimal import ROUND_HALF_UP, Context, Decimal

from .codes import I2, I4, INT_BITS, R4, R8, Num, Str, make_number
from .errors import ExceptionKind as K, StrolicError, fail
from .literals import format_real32
from .values import check_datum_size

Scalar = Num | Str
EXACT = Context(prec=1000)      # enough digits for every R8 with its places
MAX_WIDTH = 65535               # of a C conversion: wider is a conversion error


def conversion_error(detail: str) -> StrolicError:
    return fail(K.CONVERSION_ERROR, detail)


def decimal_of(num: Num) -> Decimal:
    """The exact decimal a number stands for (R4 by its shortest decimal)."""
    if num.is_integer:
        return Decimal(num.value)
    return Decimal(format_real32(num.value) if num.tag == R4 else repr(num.value))


def round_to(value: Decimal, places: int) -> Decimal:
    """Half away from zero (Annex 1 §6), to ``places`` decimals."""
    return value.quantize(Decimal(1).scaleb(-places), rounding=ROUND_HALF_UP, context=EXACT)


# ==== BASIC style: PRINT USING images ============================================================
NUMERIC_FIELD = re.compile(rb"(\++|-+)?([#%*][#%*,]*)?(\.#*)?(\^{3,})?")


class Field:
    """One format item: a numeric field, or a string field (``<<<`` left, ``>>>`` right,
    ``###`` centred when it receives a string)."""

    def __init__(self, text: bytes, sign: bytes = b"", whole: bytes = b"",
                 point: bytes | None = None, carets: bytes = b"") -> None:
        self.text = text
        self.sign = sign
        self.whole = whole.decode()
        self.places = len(point) - 1 if point else 0
        self.point = point is not None
        self.exponent_digits = len(carets) - 2 if carets else 0

    @property
    def is_string_field(self) -> bool:
        return self.text[:1] in (b"<", b">")

    def format(self, value: Scalar) -> str:
        if isinstance(value, Str):
            return self._string(value.data.decode("latin-1"))
        if self.is_string_field:
            raise conversion_error(f"a number for the string field {self.text.decode()}")
        return self._number(decimal_of(value))

    # strings
    def _string(self, text: str) -> str:
        width = len(self.text)
        if not self.is_string_field and set(self.text) != {ord("#")}:
            raise conversion_error(f"a string for the numeric field {self.text.decode()}")
        if len(text) > width:
            raise conversion_error(f"{text!r} is longer than the field {self.text.decode()}")
        if self.text[:1] == b"<":
            return text.ljust(width)
        if self.text[:1] == b">":
            return text.rjust(width)
        left = (width - len(text)) // 2
        return " " * left + text + " " * (width - len(text) - left)

    # numbers
    def _number(self, value: Decimal) -> str:
        if self.exponent_digits:
            return self._scientific(value)
        return self._plain(round_to(value, self.places))

    def _digit_positions(self) -> int:
        return sum(c in "#%*" for c in self.whole) + max(len(self.sign) - 1, 0)

    def _scientific(self, value: Decimal) -> str:
        positions = self._digit_positions()
        exponent = 0
        if value:
            exponent = value.adjusted() - positions + 1
            mantissa = round_to(value.scaleb(-exponent), self.places)
            if mantissa.copy_abs() >= Decimal(10) ** positions:      # 9.99 → 10.0
                exponent += 1
                mantissa = round_to(value.scaleb(-exponent), self.places)
        else:
            mantissa = round_to(value, self.places)
        digits = str(abs(exponent))
        if len(digits) > self.exponent_digits:
            raise conversion_error(f"exponent {exponent} does not fit {self.text.decode()}")
        return (self._plain(mantissa) + "E" + ("-" if exponent < 0 else "+")
                + digits.rjust(self.exponent_digits, "0"))

    def _plain(self, value: Decimal) -> str:
        """The sign run and the whole part filled from the right, then the point and places."""
        negative = value < 0
        whole, _, fraction = f"{abs(value):f}".partition(".")
        if whole == "0" and self.point and "%" not in self.whole:
            whole = ""                                   # #.## gives " .50", %.## "0.50"
        if negative and not self.sign:
            raise conversion_error(f"a negative number for {self.text.decode()} (no sign)")
        sign = "-" if negative else "+" if self.sign[:1] == b"+" else ""
        positions = self.sign.decode() + self.whole
        digits = list(whole)
        cells: list[str] = []                            # right to left
        for char in reversed(positions):
            if char == ",":
                cells.append(",")
            elif digits:
                cells.append(digits.pop())
            elif char == "%":
                cells.append("0")
            else:
                break
        while cells and cells[-1] == ",":                # no comma left of the first digit
            cells.pop()
        free = positions[:len(positions) - len(cells)]
        if digits or (sign and not free):
            raise conversion_error(f"{value} does not fit {self.text.decode()}")
        if sign:
            free = free[:-1]
        fill = "*" if "*" in self.whole else " "
        text = fill * len(free) + sign + "".join(reversed(cells))
        if self.point:
            text += "." + fraction.ljust(self.places, "0")
        return text


def parse_image(image: bytes) -> list[bytes | Field]:
    """The format string as literal texts and fields; a character that begins no field is
    literal text."""
    items: list[bytes | Field] = []
    literal = bytearray()
    i = 0
    while i < len(image):
        field, end = _field_at(image, i)
        if field is None:
            literal += image[i:end]
        else:
            if literal:
                items.append(bytes(literal))
                literal.clear()
            items.append(field)
        i = end
    if literal:
        items.append(bytes(literal))
    return items


def _field_at(image: bytes, i: int) -> tuple[Field | None, int]:
    """The field that begins at ``i`` and where it ends (None and i + 1 if there is none)."""
    char = image[i:i + 1]
    if char in (b"<", b">"):
        end = i
        while image[end:end + 1] == char:
            end += 1
        return Field(image[i:end]), end
    sign, whole_written, point, carets = NUMERIC_FIELD.match(image, i).groups()
    sign, whole_written = sign or b"", whole_written or b""
    whole = whole_written.rstrip(b",")               # commas after the digits are text
    if whole != whole_written:
        point = carets = None
    if not whole and not (point and len(point) > 1):
        return None, i + 1
    end = i + len(sign) + len(whole) + len(point or b"") + len(carets or b"")
    return Field(image[i:end], sign, whole, point, carets or b""), end


def basic_encode(image: bytes, values: list[Scalar]) -> bytes:
    """ENCODE1: the image is used again from its start while data remain; after the last datum
    the literal text up to the next field ends the result."""
    items = parse_image(image)
    if values and not any(isinstance(item, Field) for item in items):
        raise conversion_error("the format string has no field for the data")
    out: list[str] = []
    length = 0
    remaining = deque(values)
    while True:
        for item in items:
            if isinstance(item, bytes):
                out.append(item.decode("latin-1"))
            elif remaining:
                out.append(item.format(remaining.popleft()))
            else:
                return "".join(out).encode("latin-1")
            length += len(out[-1])
            check_datum_size(length)
        if not remaining:
            return "".join(out).encode("latin-1")


# ==== C style: sprintf ===========================================================================
def _specification(pattern: re.Pattern, template: bytes, i: int) -> re.Match:
    """The conversion specification that begins with the % at ``i``."""
    match = pattern.match(template, i)
    if match is None:
        raise conversion_error(f"bad conversion at {template[i:i + 6]!r}")
    return match


PRINT_SPEC = re.compile(rb"%(?P<flags>[-+ #0]*)(?P<width>\*|\d+)?(?:\.(?P<precision>\*|\d*))?"
                        rb"[hlL]*(?P<conversion>[diouxXeEfgGcs%])")


def _integer(value: Scalar, spec: bytes) -> int:
    if not isinstance(value, Num):
        raise conversion_error(f"%{spec.decode()} needs a number, not a string")
    if value.is_integer:
        return value.value
    return int(round_to(decimal_of(value), 0))


def _unsigned(value: Scalar, spec: bytes) -> int:
    """%o %x %X of a negative integer: the bit pattern of its type (I4 for a real)."""
    number = _integer(value, spec)
    bits = INT_BITS[value.tag] if value.is_integer else INT_BITS[I4]
    return number & ((1 << bits) - 1) if number < 0 else number


def _c_argument(conversion: bytes, value: Scalar):
    if conversion in b"diu":
        return _integer(value, conversion)
    if conversion in b"oxX":
        return _unsigned(value, conversion)
    if conversion == b"c":
        return _integer(value, conversion) & 0xFF
    if conversion == b"s":
        if not isinstance(value, Str):
            raise conversion_error("%s needs a string")
        return value.data
    if not isinstance(value, Num):
        raise conversion_error(f"%{conversion.decode()} needs a number, not a string")
    return float(value.value)       # C promotes a float to double: an R4's exact value


def _c_integer(number: int, flags: bytes, width: int, precision: int | None,
               conversion: bytes) -> bytes:
    """An integer conversion by C89's rules (4.9.6.1), which Python's % departs from: the
    precision is the least number of digits (0 of 0 with precision 0 is no digit) and turns
    the 0 flag off; + and space sign only d and i (u is d here, Annex 2); # gives o a leading
    0 and a nonzero x a 0x."""
    base = {b"o": 8, b"x": 16, b"X": 16}.get(conversion, 10)
    digits = b"" if precision == 0 and number == 0 else (
        format(abs(number), {8: "o", 16: "x", 10: "d"}[base]).encode())
    digits = digits.rjust(1 if precision is None else precision, b"0")
    if conversion == b"X":
        digits = digits.upper()
    prefix = b""
    if conversion in b"diu":
        prefix = b"-" if number < 0 else b"+" if b"+" in flags else b" " if b" " in flags else b""
    elif b"#" in flags and conversion == b"o" and not digits.startswith(b"0"):
        digits = b"0" + digits
    elif b"#" in flags and number != 0 and conversion in b"xX":
        prefix = b"0" + conversion
    pad = width - len(prefix) - len(digits)
    if pad <= 0:
        return prefix + digits
    if b"-" in flags:
        return prefix + digits + b" " * pad
    if b"0" in flags and precision is None:
        return prefix + b"0" * pad + digits
    return b" " * pad + prefix + digits


def c_encode(template: bytes, values: list[Scalar]) -> bytes:
    """ENCODE2: ``sprintf``; extra data are ignored, too few are a conversion error."""
    out = bytearray()
    remaining = deque(values)

    def take(what: str) -> Scalar:
        if not remaining:
            raise conversion_error(f"no datum left for {what}")
        return remaining.popleft()

    i = 0
    while i < len(template):
        if template[i:i + 1] != b"%":
            out += template[i:i + 1]
            i += 1
            continue
        match = _specification(PRINT_SPEC, template, i)
        i = match.end()
        flags, width, precision, conversion = match.group("flags", "width", "precision",
                                                          "conversion")
        if conversion == b"%":
            out += b"%"
            continue
        if width == b"*":
            number = _integer(take("a * width"), b"*")
            flags += b"-" if number < 0 else b""
            width = str(abs(number)).encode()
        if precision == b"*":
            number = _integer(take("a * precision"), b"*")
            precision = str(number).encode() if number >= 0 else None
        if any(part and part != b"*" and int(part) > MAX_WIDTH for part in (width, precision)):
            raise conversion_error(f"a width or precision above {MAX_WIDTH}")
        argument = _c_argument(conversion, take(f"%{conversion.decode()}"))
        if conversion in b"diuoxX":
            out += _c_integer(argument, flags, int(width or 0),
                              None if precision is None else int(precision or 0), conversion)
        else:
            out += (b"%" + flags + (width or b"") + (b"." + precision if precision is not None
                                                     else b"") + conversion) % argument
        check_datum_size(len(out))
    return bytes(out)


# ==== C style: sscanf ============================================================================
SCAN_SPEC = re.compile(rb"%(?P<suppress>\*)?(?P<width>\d+)?[hlL]*"
                       rb"(?P<conversion>[diouxXeEfgGcs%]|\[\^?\]?[^\]]*\])")
SCAN_PATTERNS = {
    b"d": rb"[+-]?\d+", b"u": rb"[+-]?\d+", b"i": rb"[+-]?(0[xX][0-9a-fA-F]+|0[0-7]*|[1-9]\d*)",
    b"o": rb"[+-]?[0-7]+", b"x": rb"[+-]?(0[xX])?[0-9a-fA-F]+",
    b"e": rb"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?", b"s": rb"\S+",
}
SCAN_PATTERNS.update({b"X": SCAN_PATTERNS[b"x"], b"f": SCAN_PATTERNS[b"e"],
                      b"g": SCAN_PATTERNS[b"e"], b"E": SCAN_PATTERNS[b"e"],
                      b"G": SCAN_PATTERNS[b"e"]})
BASES = {b"d": 10, b"u": 10, b"i": 0, b"o": 8, b"x": 16, b"X": 16}
WHITE = b" \t\n\r\f\v"


def _scan_set(conversion: bytes) -> bytes:
    """``[abc]``, ``[^abc]``, ``[]a]``, ``[a-z]`` as a regular expression of one or more such
    bytes; an empty set or a range that runs backwards is a conversion error."""
    body = conversion[1:-1]
    negate = body.startswith(b"^")
    body = body[1:] if negate else body
    if not body:
        raise conversion_error(f"%{conversion.decode(errors='replace')}: an empty scan set")
    escaped = b""
    for i, b in enumerate(body):
        if b == ord("-") and 0 < i < len(body) - 1:
            if body[i - 1] > body[i + 1]:
                raise conversion_error(f"%{conversion.decode(errors='replace')}: the range "
                                       f"{chr(body[i - 1])}-{chr(body[i + 1])} runs backwards")
            escaped += b"-"
        else:
            escaped += re.escape(bytes([b]))
    return b"[" + (b"^" if negate else b"") + escaped + b"]+"


def assignments(template: bytes) -> int:
    """How many conversions of a ``sscanf`` format store a value."""
    return sum(1 for match in SCAN_SPEC.finditer(template)
               if not match.group("suppress") and match.group("conversion") != b"%")


def c_decode(template: bytes, data: bytes) -> tuple[list[Scalar], int]:
    """DECODE2: ``sscanf``. Returns the values stored, in order, and the count pushed: the
    number of values stored, or −1 when the data ended before the first conversion."""
    values: list[Scalar] = []
    position = 0
    i = 0
    conversions = 0

    def result() -> tuple[list[Scalar], int]:
        return values, (-1 if conversions == 0 and position >= len(data) else len(values))

    while i < len(template):
        char = template[i:i + 1]
        if char in WHITE:
            while position < len(data) and data[position:position + 1] in WHITE:
                position += 1
            i += 1
            continue
        if char != b"%":
            if data[position:position + 1] != char:
                return result()
            position += 1
            i += 1
            continue
        match = _specification(SCAN_SPEC, template, i)
        i = match.end()
        suppress, width, conversion = match.group("suppress", "width", "conversion")
        limit = int(width) if width else None
        if limit == 0:
            raise conversion_error("a field width of 0")
        if conversion[:1] not in (b"c", b"["):
            while position < len(data) and data[position:position + 1] in WHITE:
                position += 1
        if position >= len(data):
            return result()
        window = data[position:position + limit] if limit else data[position:]
        if conversion == b"%":
            if window[:1] != b"%":
                return result()
            position += 1
            continue
        if conversion == b"c":
            if limit not in (None, 1):
                raise conversion_error("%c reads one character (an integer)")
            text, value = window[:1], Num(I2, window[0])
        else:
            pattern = (_scan_set(conversion) if conversion[:1] == b"["
                       else SCAN_PATTERNS[conversion])
            found = re.match(pattern, window)
            if found is None:
                return result()
            text = found.group()
            value = _scanned(conversion, text)
        position += len(text)
        conversions += 1
        if not suppress:
            values.append(value)
    return result()


def _scanned(conversion: bytes, text: bytes) -> Scalar:
    if conversion in BASES:
        base = BASES[conversion]
        if base == 0:           # %i as C reads it: 0x… hexadecimal, 0… octal, else decimal
            digits = text.lstrip(b"+-")
            base = (16 if digits[:2] in (b"0x", b"0X") else 8 if digits[:1] == b"0" else 10)
        number = int(text, base)
        try:
            return make_number(I4, number)
        except StrolicError:
            raise conversion_error(f"{text.decode()} does not fit I4") from None
    if conversion == b"s" or conversion[:1] == b"[":
        return Str(bytes(text))
    return make_number(R8, float(text))
