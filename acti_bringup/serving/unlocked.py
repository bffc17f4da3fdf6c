"""Messages, responses and the actions' feedback and answers handed to rcl with the GIL released.

rclpy publishes and responds inside one C call that holds the GIL throughout, and Fast DDS can
hold such a call for a third of a second (`acti_bringup.serving.outbox` says when): every
thread of the process then waits. Here a Python message is converted to its C message under the
GIL (rosidl's own conversion, the one rclpy uses), and the send itself (`rcl_publish`,
`rcl_send_response`, `rcl_action_publish_feedback`, `rcl_action_send_*_response`) is called
through ctypes, which releases
the GIL for the call.

rclpy gives Python no access to a request header's writer GUID, which rcl needs. The header is
a pybind11 object whose first slot holds the address of its C `rmw_request_id_t`; that address
is used only when the sequence number read through it is the one rclpy reports, else (another
rclpy layout) the response goes through rclpy as before.

A client answered before is answered in one foreign call (`respond`, of the C extension that
`make setup` builds: acti_bringup/serving/_respond.c), which reads the header the same way.
"""
from __future__ import annotations

import ctypes
import functools
import os
from typing import Any, Callable

from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy

try:
    from acti_bringup.serving import _respond as respond
except ImportError:          # not built (a checkout before `make setup`): every response goes
    respond = None           # through the outbox

RCL_RET_OK = 0
RCL_RET_TIMEOUT = 2
_SEQUENCE_OFFSET = 16            # rmw_request_id_t: int8_t writer_guid[16]; int64_t sequence_number
_REQUEST_ID_SIZE = 24
_VALUE_SLOT = ctypes.sizeof(ctypes.c_ssize_t) + ctypes.sizeof(ctypes.c_void_p)   # after PyObject_HEAD
_REQUEST_IN_INFO = 16            # rmw_service_info_t: int64_t source_timestamp, received_timestamp;
                                 # rmw_request_id_t request_id
if respond is not None:
    respond.expect(_rclpy.rmw_service_info_t, _VALUE_SLOT, _REQUEST_IN_INFO)

_capsule_pointer = ctypes.pythonapi.PyCapsule_GetPointer
_capsule_pointer.restype = ctypes.c_void_p
_capsule_pointer.argtypes = (ctypes.py_object, ctypes.c_char_p)

# Under the GIL (they touch Python objects or are too short to be worth a release).
_CREATE = ctypes.PYFUNCTYPE(ctypes.c_void_p)
_DESTROY = ctypes.PYFUNCTYPE(None, ctypes.c_void_p)
_CONVERT = ctypes.PYFUNCTYPE(ctypes.c_bool, ctypes.py_object, ctypes.c_void_p)


class _ErrorString(ctypes.Structure):
    _fields_ = [("str", ctypes.c_char * 1024)]


class Rcl:
    """librcl, librcl_action and librcutils as rclpy loaded them (RTLD_NOLOAD: the same
    copies), their send functions typed."""

    def __init__(self) -> None:
        mode = os.RTLD_NOLOAD | os.RTLD_GLOBAL
        rcl, action = ctypes.CDLL("librcl.so", mode=mode), ctypes.CDLL("librcl_action.so", mode=mode)
        self._rcutils = ctypes.CDLL("librcutils.so", mode=mode)
        self.send_response, self.publish = rcl.rcl_send_response, rcl.rcl_publish
        for fn in (self.send_response, self.publish):
            fn.restype, fn.argtypes = ctypes.c_int, (ctypes.c_void_p,) * 3
        self.publish_feedback = action.rcl_action_publish_feedback
        self.publish_feedback.restype = ctypes.c_int
        self.publish_feedback.argtypes = (ctypes.c_void_p,) * 2
        # an action server's answers, by the name of rclpy's method that sends them
        self.action_answers = {f"send_{kind}_response": getattr(action, f"rcl_action_send_{kind}_response")
                               for kind in ("goal", "cancel", "result")}
        for fn in self.action_answers.values():
            fn.restype, fn.argtypes = ctypes.c_int, (ctypes.c_void_p,) * 3
        self._rcutils.rcutils_get_error_string.restype = _ErrorString
        self._rcutils.rcutils_reset_error.restype = None
        self.send_response_address = ctypes.cast(self.send_response, ctypes.c_void_p).value

    def error(self) -> str:
        """rcl's last error message (and clear it)."""
        reason = self._rcutils.rcutils_get_error_string().str.decode(errors="replace")
        self._rcutils.rcutils_reset_error()
        return reason


@functools.lru_cache(maxsize=1)
def rcl() -> Rcl | None:
    """The rcl libraries, loaded once; None where rclpy's are not found (rclpy then sends)."""
    try:
        return Rcl()
    except (OSError, AttributeError):
        return None


def sent(ret: int) -> bool:
    """rcl's return code of a send: True when sent, False on a timeout, else RuntimeError."""
    if ret == RCL_RET_OK:
        return True
    reason = rcl().error()
    if ret == RCL_RET_TIMEOUT:
        return False
    raise RuntimeError(f"rcl could not send it ({ret}): {reason}")


class CMessage:
    """A Python message converted to its C message (under the GIL, at once, so that later
    changes to the Python message do not reach it), sent later without the GIL."""

    __slots__ = ("_kind", "_pointer")

    def __init__(self, kind: "MessageKind", msg: Any) -> None:
        self._kind, self._pointer = kind, kind.convert(msg)

    def send(self, entity: Any, rcl_send: Callable[[int, int], int], keep: bool = False) -> bool:
        """rcl_send(entity pointer, C message), GIL-free: True when sent, False on an rcl
        timeout, RuntimeError otherwise. `entity`: rclpy's handle, kept alive meanwhile (an
        InvalidHandle error once it is destroyed). The C message is freed either way, unless
        `keep` (to be sent again: rcl only reads it; `discard` frees it)."""
        try:
            with entity:
                ret = rcl_send(entity.pointer, self._pointer)
        finally:
            if not keep:
                self.discard()
        return sent(ret)

    @property
    def address(self) -> int:
        """The C message's address (0 once freed)."""
        return self._pointer or 0

    def discard(self) -> None:
        """Free the C message (unsent)."""
        if self._pointer:
            self._kind.destroy(self._pointer)
            self._pointer = None


class MessageKind:
    """rosidl's create, convert and destroy of one message type (its capsules)."""

    def __init__(self, msg_class: type) -> None:
        meta = type(msg_class)
        self.msg_class = msg_class
        self.addresses = tuple(_capsule_pointer(capsule, None) for capsule in (
            meta._CREATE_ROS_MESSAGE, meta._CONVERT_FROM_PY, meta._DESTROY_ROS_MESSAGE))
        self._create, self._convert, self.destroy = (
            fn_type(address) for fn_type, address in zip((_CREATE, _CONVERT, _DESTROY),
                                                         self.addresses))

    def check(self, msg: Any) -> None:
        """TypeError for a message of another type, as rclpy refuses it."""
        if not isinstance(msg, self.msg_class):
            raise TypeError(f"expected a {self.msg_class.__name__}, got a {type(msg).__name__}")

    def convert(self, msg: Any) -> int:
        """A new C message holding `msg` (`check`ed)."""
        self.check(msg)
        pointer = self._create()
        if not pointer:
            raise MemoryError(f"no memory for a {self.msg_class.__name__}")
        if not self._convert(msg, pointer):
            self.destroy(pointer)
            raise RuntimeError(f"the {self.msg_class.__name__} could not be converted")
        return pointer


GUID_BYTES = 16             # rmw_request_id_t.writer_guid: the client's request writer


def request_id(address: int) -> ctypes.Array:
    """A copy of the C rmw_request_id_t at `address` (`header_address`): rclpy's may not
    outlive the request's callback."""
    return ctypes.create_string_buffer(ctypes.string_at(address, _REQUEST_ID_SIZE),
                                       _REQUEST_ID_SIZE)


def header_address(header: Any) -> int | None:
    """The address of the C rmw_request_id_t behind rclpy's header, when it checks out."""
    if isinstance(header, _rclpy.rmw_service_info_t):
        header = header.request_id
    if type(header) is not _rclpy.rmw_request_id_t:
        return None
    address = ctypes.c_void_p.from_address(id(header) + _VALUE_SLOT).value
    if not address:
        return None
    sequence = ctypes.c_int64.from_address(address + _SEQUENCE_OFFSET).value
    return address if sequence == header.sequence_number else None
