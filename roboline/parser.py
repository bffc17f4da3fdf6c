"""The RoboLine grammar (grammar.lark) read by lark's LALR parser: text → tree, or a
`SourceError` that names the place and what was expected there."""
from __future__ import annotations

import hashlib
import os
from functools import lru_cache
from pathlib import Path

import lark

from .source import Source, SourceError

GRAMMAR = Path(__file__).with_name("grammar.lark")

# how an error names the terminals lark expected (the others by their text)
TERMINAL_NAMES = {"_NL": "the end of the line", "NAME": "a name", "NUMBER": "a number",
                  "STRING": "a string", "LABEL": "a label (*name)", "$END": "the end"}


@lru_cache(maxsize=1)
def parser() -> lark.Lark:
    """Built once a process. Its LALR tables are kept in the user's cache directory (lark
    checks they are of this grammar, lark and Python), so that a new process (the command,
    a node) loads them instead of building them: ~40 ms -> ~5-15 ms CPU."""
    text = GRAMMAR.read_text()
    options = {"parser": "lalr", "maybe_placeholders": True}
    cache = (Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "roboline"
             / f"grammar-{hashlib.md5(text.encode()).hexdigest()}.lark")
    try:
        cache.parent.mkdir(parents=True, exist_ok=True)
        return lark.Lark(text, cache=str(cache), **options)
    except OSError:             # no cache where none can be written
        return lark.Lark(text, **options)


def parse(source: Source) -> lark.Tree:
    text = source.text if source.text.endswith("\n") else source.text + "\n"
    try:
        return parser().parse(text)
    except lark.exceptions.UnexpectedToken as e:
        found = {"_NL": "the end of the line", "$END": "the end"}.get(e.token.type,
                                                                     repr(str(e.token)))
        raise SourceError(source, e.line, e.column,
                          f"unexpected {found}; expected {expected(e.expected)}") from None
    except lark.exceptions.UnexpectedCharacters as e:
        raise SourceError(source, e.line, e.column,
                          f"unexpected character {text[e.pos_in_stream]!r}; expected "
                          f"{expected(e.allowed)}") from None
    except lark.exceptions.UnexpectedEOF as e:    # the text always ends in a newline
        lines = text.splitlines()
        raise SourceError(source, len(lines), len(lines[-1]) + 1,
                          f"unexpected end; expected {expected(e.expected)}") from None


def expected(names) -> str:
    shown = sorted({describe(name) for name in names})
    return shown[0] if len(shown) == 1 else "one of: " + ", ".join(shown)


def describe(terminal: str) -> str:
    if terminal in TERMINAL_NAMES:
        return TERMINAL_NAMES[terminal]
    try:
        pattern = parser().get_terminal(terminal).pattern
    except KeyError:
        return terminal
    return repr(pattern.value.upper()) if pattern.type == "str" else terminal
