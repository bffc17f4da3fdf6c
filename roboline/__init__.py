"""RoboLine: a line-oriented robot language (in the style of SLIM, JIS B 8439, and the robot
makers' languages) compiled to standard STROLIC (JIS B 8440) codes, with a source map."""
from .compiler import compile_source
from .points import parse_points
from .program import Program, Symbol
from .source import Source, SourceError

__all__ = ["compile_source", "parse_points", "Program", "Symbol", "Source", "SourceError"]
