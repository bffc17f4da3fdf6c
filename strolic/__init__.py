"""STROLIC (JIS B 8440-1995) for acti_ros2: codec, text form and virtual machine (see README.md)."""
from .codec import decode, encode
from .errors import ExceptionKind, StrolicError
from .host import Host
from .text import assemble, disassemble
from .vm import VM

__all__ = ["VM", "Host", "StrolicError", "ExceptionKind", "assemble", "disassemble", "decode",
           "encode"]
