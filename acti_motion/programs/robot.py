"""STROLIC robot-control functions ED00–ED23 on the arm: `RobotHost`, the VM's host for programs
that move the arm (the middle-level spec's high level, JOB execution).

Every motion a program commands goes into the arm's one motion queue, the queue the services
use, so program and service motions run in the order they were sent. A program keeps its own
modal settings (JSPEED, SPEED, ACCEL/DECEL, SACC, configuration, hands), the services theirs.
Units (the ACT ports'): lengths mm, joint values degree, SPEED mm/s, JSPEED %, times s.

Blocking functions ($WAIT, DELAY, CALIB, a motion command on a full queue) wait the VM's way:
the process waits and the scheduler looks again every `POLL` seconds of simulated time; the
host's clock is the simulation's. `check` (between slices) turns what happens to the program's
motions outside it into exceptions: an alarm, a stop or servo-off that discarded one of them,
and a cancel of the run; `stop` (the program stopped on an exception) stops the arm (§4.5).
The choices where the standard leaves things to the implementation are in strolic/README.md.
"""
from __future__ import annotations

import math
import struct
import sys
import threading
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING, Callable

import numpy as np

from acti_motion.arm.core import (SERVO_OFF_REASON, STATE_ALARM, STATE_MOVING, STATE_PAUSED,
                                  ArmCore)
from acti_motion.arm.blending import ARM_MOVES, blend_with_previous
from acti_motion.arm.kinematics import Unreachable, rotate_about
from acti_motion.arm.poses import compose_relative, hg_to_pose, inverse
from acti_motion.config_fields import check_ranges, ranged
from acti_motion.replies import Refused, ReturnCode, value_error
from acti_motion.arm.trajectories import ArcPath, ArmSetpoint, LinePath
from strolic.codes import (I2, NUMERIC_TAGS, POSE, R4, R8, Array, Num, Pose, Str, TagHead,
                           Trn, make_real, type_name)
from strolic.errors import ExceptionKind as K, StrolicError, fail
from strolic.functions.args import integer_value, pop_many, pop_num, pop_of
from strolic.functions.geometry import matrix_of, pose_of, pose_parts
from strolic.host import Host, MemoryIO
from strolic.process import WAIT, Process, State
from strolic.values import array_elements

CANCELED = "the run was canceled"          # what a canceled run's exception says

if TYPE_CHECKING:
    from strolic.opcodes import Opcode
    from strolic.vm import VM

# error flags of the setting, motion and hand functions (0: no exception)
FLAG_INVALID = 1        # a value out of its range, an undefined pose, a wrong count
FLAG_RANGE = 2          # outside the motion range: soft limits, unreachable, singular path
FLAG_CONFIGURATION = 3  # a Cartesian move to a pose of another configuration than the arm's
FLAG_NOT_READY = 4      # servo off, an alarm active, or the speed is 0
FLAG_HAND = 5           # the hand is not defined, or too many hands
# $WAIT / $DONE on an abnormal end (the same event also stops the program, see `check`)
STATUS_DISCARDED = -1
STATUS_ALARM = -2

CONSOLE_LINE = 4096            # characters of a console line kept for the result …
CONSOLE_BYTES = 1 << 20        # … and of all of them
POLL = 1.0 / 120.0             # s (simulated) between two looks of a waiting function
REST_POLL_S = 0.002            # s (wall) between two looks at a stopping arm
REST_TIMEOUT_S = 60.0          # s (wall): the longest stop (10 s accel time) at real-time factor ⅙
MAX_DELAY = 86400.0            # s
MAX_ACCURACY = 100.0           # mm: SACC radius
MAX_RAMP = 10.0                # s: ACCEL2 / DECEL2
ARC_RADIUS_LIMIT = 2000.0      # mm: CMOVE1/CMOVE3 beyond it are linear moves
MAX_HANDS = 8
MAX_HAND_NUMBER = 99
STATUS_PORT = 16               # input port with the robot's status bits
STATUS_BITS = ("servo on", "moving", "alarm", "paused", "hand closed", "hand open")
HAND_TOLERANCE_MM = 1.0
CONFIGURATION_BITS = 0b111
PLANES = {1: 2, 2: 0, 3: 1}    # CMOVE1 plane → its normal axis: xy → z, yz → x, zx → y

# a robot-control function of `FUNCTIONS`, called unbound with the host: it returns WAIT when
# the process must wait (the VM calls it again later), else None
Handler = Callable[["RobotHost", "VM", Process], object]


@dataclass
class ProgramDefaults:
    """The modal settings a program starts with (the node's parameters)."""
    program_jspeed: float = ranged(20.0, 0.0, 100.0)    # JSPEED at the start of a program [%]
    # SPEED at the start of a program [mm/s] (at most the arm's max_speed_translation)
    program_speed: float = ranged(100.0, 0.0, 10000.0)


class Flag(Exception):
    """A function's error flag (an exception the function reports by its result)."""

    def __init__(self, code: int, reason: str) -> None:
        super().__init__(reason)
        self.code = code
        self.reason = reason


def refused_flag(refused: Refused) -> Flag:
    code = FLAG_RANGE if refused.code == ReturnCode.VALUE_ERR else FLAG_NOT_READY
    return Flag(code, refused.comment)


@dataclass(frozen=True)
class Target:
    """A pose of the hand's tool point: 4×4 (m, robot frame), configuration bits, elbow (deg)."""
    pose: np.ndarray
    configuration: int
    elbow: float


@dataclass
class Hand:
    """HANDDEF: the parameters as given (HANDREF returns them) and what they mean here."""
    params: tuple = ()
    tool: np.ndarray | None = None     # tool point seen from the control point (4×4, m)
    open_mm: float | None = None       # HANDOPEN opening (None: fully open)
    close_mm: float = 0.0              # HANDCLOSE opening


class RobotIO(MemoryIO):
    """Digital I/O of the robot: ports 1–8 (8 bits) and 9–15 (16 bits) are outputs wired back
    to the inputs of the same number (a simulated device or a test may set them too); input
    port 16 holds the robot's status (`STATUS_BITS`, bit 0 first) and is no output."""

    def __init__(self) -> None:
        super().__init__({p: 8 if p <= 8 else 16 for p in range(1, STATUS_PORT)})


class InHand:
    """A path of the hand's tool point seen as the path of the control point (what the arm
    plans): the same progress, poses moved by the inverse tool frame."""

    def __init__(self, path: LinePath, tool: np.ndarray) -> None:
        self.path, self._inverse = path, inverse(tool)
        self.length, self.angle = path.length, path.angle

    def pose(self, s: float) -> np.ndarray:
        return self.path.pose(s) @ self._inverse

    def position(self, s: float) -> np.ndarray:
        return self.pose(s)[:3, 3]


class CirclePath(LinePath):
    """CMOVE1's arc: the start position turned by `sweep` (rad) about `axis` through `centre`;
    the orientation turns with it (`turning`) or follows the geodesic to P1's."""

    def __init__(self, P0: np.ndarray, centre: np.ndarray, axis: np.ndarray, sweep: float,
                 P1: np.ndarray, turning: bool) -> None:
        super().__init__(P0, P1)
        self.centre, self.axis, self.sweep, self.turning = centre, axis, sweep, turning
        self._r0 = P0[:3, 3] - centre
        self.length = float(np.linalg.norm(self._r0)) * abs(sweep)
        if turning:
            self.angle = abs(sweep)

    def position(self, s: float) -> np.ndarray:
        return self.centre + rotate_about(self.axis, s * self.sweep) @ self._r0

    def pose(self, s: float) -> np.ndarray:
        T = super().pose(s)
        if self.turning:
            T[:3, :3] = rotate_about(self.axis, s * self.sweep) @ self.R0
        T[:3, 3] = self.position(s)
        return T


def _wait_key(proc: Process) -> tuple:
    return id(proc), id(proc.frame), proc.frame.pc



def _shown_line(text: str) -> str:
    """A console line or a PAUSE message as shown (result, progress): at most CONSOLE_LINE
    characters, a longer one cut with its length said."""
    if len(text) > CONSOLE_LINE:
        return f"{text[:CONSOLE_LINE]}… ({len(text)} characters)"
    return text


def _push_flag(proc: Process, code: int) -> None:
    proc.push(Num(I2, code))


class RobotHost(Host):
    """The host of a program run on the arm (one per run). `step`, when given, advances the
    simulation while the program waits (tests that step the executor themselves); otherwise the
    executor's thread runs and waiting sleeps."""

    def __init__(self, arm: ArmCore, io: MemoryIO | None = None, *,
                 step: Callable[[], None] | None = None,
                 defaults: ProgramDefaults | None = None, echo: bool = False) -> None:
        super().__init__()
        d = defaults or ProgramDefaults()
        check_ranges(d, "program defaults")
        self.arm = arm
        self.io = io or RobotIO()
        self.step = step
        self.echo = echo
        self.lines: list[str] = []
        self.lines_dropped = 0
        self._console_size = 0
        self.jspeed = d.program_jspeed
        self.speed = min(d.program_speed, arm.max_speed_cartesian[0])   # what SPEED would take
        self.accel: tuple[str, float] | None = None     # ("percent" | "time", value)
        self.decel: tuple[str, float] | None = None
        self.accuracy = 0.0                               # SACC, mm
        self.hands: dict[int, Hand] = {1: Hand()}
        self.hand = 1
        self.last_motion = 0                              # id of the latest motion commanded
        self.pending: set[int] = set()                    # its motions not yet over
        self.abnormal = 0                                 # STATUS_* once one ended abnormally
        self.state = "running"                            # for progress reports
        self.message = ""
        self.cancel_event = threading.Event()
        self._alarms0 = {a.as_tuple() for a in arm.alarms}
        self._fault: tuple[K, str] | None = None
        self._waits: dict[tuple, object] = {}
        self._frozen = 0.0                                # s of pause and interrupts (DELAY)
        self._last_check = self.now()

    # === the VM's hooks =========================================================================
    def call(self, vm: VM, proc: Process, opcode: Opcode) -> object:
        method = FUNCTIONS.get(opcode.mnemonic)
        if method is None:
            return super().call(vm, proc, opcode)
        return method(self, vm, proc)

    def console(self, text: str) -> None:
        """A console line (TRACE, warnings, flags, PAUSE messages), kept for the run's result:
        at most CONSOLE_LINE characters each and CONSOLE_BYTES in all; lines beyond are only
        counted (a traced 4 MiB string, ten times, put 168 MB into the result)."""
        text = _shown_line(text)
        if self._console_size + len(text) > CONSOLE_BYTES:
            self.lines_dropped += 1
        else:
            self.lines.append(text)
            self._console_size += len(text)
        if self.echo:
            print(text, file=sys.stderr)

    def now(self) -> float:
        return self.arm.executor.world.time

    def sleep(self, seconds: float) -> None:
        """Let `seconds` of simulated time pass (at least one control cycle), or until canceled."""
        executor = self.arm.executor
        end = self.now() + max(seconds, executor.dt)
        while self.now() < end - 1e-9 and not self.cancel_event.is_set():
            if self.step is not None:
                self.step()
            else:
                factor = executor.real_time_factor
                wall = (end - self.now()) / factor if factor > 0 else 0.0
                self.cancel_event.wait(min(max(wall, 0.0005), 0.05))

    def check(self, vm: VM) -> None:
        if self.cancel_event.is_set():
            raise fail(K.STOPPED, CANCELED)
        now = self.now()
        if self._interrupted(vm):
            self._frozen += now - self._last_check
        self._last_check = now
        self._collect()

    def stop(self, error: StrolicError) -> None:
        """The program stopped on an exception: the arm decelerates and its queue is discarded."""
        self.state = "stopping"
        self.arm.stop_motion(reason=f"the program's end: {error}")

    def wait_at_rest(self) -> None:
        """After a stop: until the arm is at rest, so that a run ends with the robot stopped
        (§4.5) and its client can start again at once (a canceled run answered while the arm
        still decelerated, and the next program's first move was discarded by that stop), its
        joints settled (the state word says not moving)."""
        device, executor = self.arm.device, self.arm.executor
        deadline = time.monotonic() + REST_TIMEOUT_S
        while (device.stopping or self.arm.settling) and time.monotonic() < deadline:
            if self.step is not None:
                self.step()
            elif executor.running:
                time.sleep(REST_POLL_S)
            else:               # the simulation ended (shutdown): nothing will come to rest
                return

    # digital I/O: RobotIO, and the status port
    def io_port_bits(self, port: int, output: bool) -> int | None:
        if port == STATUS_PORT:
            return None if output else 16
        return super().io_port_bits(port, output)

    def read_io(self, port: int) -> int:
        return self.status_bits() if port == STATUS_PORT else super().read_io(port)

    def status_bits(self) -> int:
        arm = self.arm
        word = arm.state_word()
        opening = arm.get_feedback_pos_joint().values["pos"][7]
        hand = self.hands.get(self.hand) or Hand()       # the openings of the hand in use
        open_mm = self.max_opening if hand.open_mm is None else hand.open_mm
        flags = {"servo on": arm.servo, "moving": bool(word & STATE_MOVING),
                 "alarm": bool(word & STATE_ALARM), "paused": bool(word & STATE_PAUSED),
                 "hand closed": opening < hand.close_mm + HAND_TOLERANCE_MM,
                 "hand open": opening > open_mm - HAND_TOLERANCE_MM}
        return sum(1 << i for i, name in enumerate(STATUS_BITS) if flags[name])

    # === the program's motions ===================================================================
    def _issued(self, motion_id: int) -> None:
        """A motion the program commanded: blend it with the one before (SACC), remember it."""
        previous = self.last_motion
        if self.accuracy > 0 and previous == motion_id - 1:
            tool = self.tool
            blend_with_previous(self.arm.device, motion_id, previous, self.accuracy / 1000.0,
                                lambda q: (self.arm.tool_pose(q) @ tool)[:3, 3])
        self.last_motion = motion_id
        self.pending.add(motion_id)

    def _collect(self) -> None:
        """Forget the motions that are over; a new alarm or a discarded motion of the program
        is an exception (raised again at every later call: the program must stop)."""
        if self._fault is None:
            self._fault = self._find_fault()
        if self._fault is not None:
            raise fail(*self._fault)

    def _find_fault(self) -> tuple[K, str] | None:
        arm, device = self.arm, self.arm.device
        new = [a for a in arm.alarms if a.as_tuple() not in self._alarms0]
        if new:
            self.abnormal = STATUS_ALARM
            kind = K.OUT_OF_OPERATING_REGION if new[0].code in (4, 5) else K.ROBOT_ERROR
            return kind, f"alarm 0x{new[0].code:X}: {new[0].description}"
        over = {i for i in self.pending if device.is_over(i)}   # not while a stop decelerates it
        self.pending -= over
        lost = sorted(i for i in over if device.was_discarded(i))
        if not lost:
            return None
        self.abnormal = STATUS_DISCARDED
        reason = device.discard_reason(lost[0])
        why = f"motion {lost[0]} of the program was discarded: {reason}"
        # by what discarded it, not by the servo now (a servo_on right after read as a stop)
        servo_off = reason == SERVO_OFF_REASON or not arm.servo
        return (K.SERVO_ERROR if servo_off else K.ROBOT_ERROR), why

    def motion_status(self) -> int:
        """$DONE: 0 over, 1 the robot moves, 2 only the hand moves, 3 both, < 0 abnormal end."""
        self._collect_quietly()
        if self.abnormal:
            return self.abnormal
        if not self.pending:
            return 0
        device = self.arm.device
        with device.lock:
            entries = ([device.current] if device.current is not None else []) + list(device.queue)
            kinds = {e.motion.kind for e in entries if e.id in self.pending}
        status = (1 if kinds & set(ARM_MOVES) else 0) | (2 if "gripper" in kinds else 0)
        return status or 1

    def _collect_quietly(self) -> None:
        try:
            self._collect()
        except StrolicError:
            pass

    def hold(self, vm: VM, debugger) -> None:
        """At a breakpoint (`debugger.LineVM`): once the program's motions so far have ended,
        wait for a step or continue; a stop, cancel or alarm meanwhile is the exception as ever."""
        self.check(vm)
        while self.pending:
            self.sleep(POLL)
            self.check(vm)
        debugger.arrive()
        previous, self.state = self.state, "at breakpoint"
        try:
            while not debugger.wait_for_go(0):
                self.sleep(POLL)
                self.check(vm)
        finally:
            debugger.leave()
            self.state = previous

    def wait_motions(self, vm: VM) -> None:
        """After the program's end: wait until its motions are over (exceptions as `check`)."""
        self.state = "finishing motions"
        self.check(vm)
        while self.pending:
            self.sleep(POLL)
            self.check(vm)

    # === helpers ==================================================================================
    @property
    def max_opening(self) -> float:
        return 2000.0 * self.arm.finger_max

    @property
    def tool(self) -> np.ndarray:
        hand = self.hands.get(self.hand)
        return hand.tool if hand is not None and hand.tool is not None else np.eye(4)

    def _interrupted(self, vm: VM) -> bool:
        return any(isinstance(k, str) and p.state is not State.DONE
                   for k, p in vm.processes.items())

    def _flag(self, proc: Process, name: str, error: Flag | None) -> None:
        if error is not None:
            self.console(f"{name}: error flag {error.code}: {error.reason}")
        _push_flag(proc, 0 if error is None else error.code)

    def _ramp(self, kind: str) -> float:
        """Accel/decel time (s) of a move: the longer of the ACCEL and DECEL settings (the
        profiles are symmetric; one that is not set follows the other), the port's accel time
        while neither is set; at most MAX_RAMP, since a stop decelerates over it (ACCEL1 takes
        any percentage above 0: 0.001 % made 10 000 s, and a stop that never ended)."""
        arm = self.arm
        joint = kind == "joint"
        minimum = arm.min_accel_time_joint if joint else arm.min_accel_time_cartesian
        default = arm.accel_time_joint if joint else arm.accel_time_cartesian

        def of(setting: tuple[str, float] | None) -> float:
            if setting is None:
                return default
            how, value = setting
            return minimum * 100.0 / value if how == "percent" else value
        return min(max(of(self.accel or self.decel), of(self.decel or self.accel), minimum),
                   MAX_RAMP)

    def _cartesian_ratio(self) -> float:
        return 100.0 * self.speed / self.arm.max_speed_cartesian[0]

    def _start(self) -> tuple[np.ndarray, Target]:
        """Joints where the queued motions end, and the hand there (relative moves start here)."""
        q = self.arm.device.queued_end.joints
        kin = self.arm.kin
        return q, Target(self.arm.tool_pose(q) @ self.tool, kin.flags(q),
                         math.degrees(kin.arm_angle(q)))

    def hand_pose(self, q: np.ndarray) -> Pose:
        kin = self.arm.kin
        T = self.arm.tool_pose(q) @ self.tool
        matrix = T.copy()
        matrix[:3, 3] *= 1000.0
        return pose_of(matrix, kin.flags(q), math.degrees(kin.arm_angle(q)))

    @staticmethod
    def target_of(pose: Pose) -> Target:
        """The hand pose a Pm gives; an undefined pose (not this layout, no rotation) is a flag."""
        try:
            matrix, configuration, elbow = pose_parts(pose)
        except StrolicError as e:
            raise Flag(FLAG_INVALID, f"undefined pose: {e.detail}") from None
        try:
            T = hg_to_pose([float(x) for x in matrix[:3, :4].reshape(-1)], "pose")
        except Refused as r:
            raise Flag(FLAG_INVALID, f"undefined pose: {r.comment}") from None
        if not math.isfinite(elbow):
            raise Flag(FLAG_INVALID, "undefined pose: the elbow angle is not finite")
        return Target(T, configuration & CONFIGURATION_BITS, elbow)

    def _targets(self, item: Pose | Array) -> list[Target]:
        """A Pm or an Ar of Pm (a pose sequence) as targets."""
        poses = [item] if isinstance(item, Pose) else array_elements(item)
        if not poses:
            raise Flag(FLAG_INVALID, "an empty pose sequence")
        return [self.target_of(p) for p in poses]

    @staticmethod
    def _count_of(item: object) -> int:
        if isinstance(item, Array) and item.element.tag == POSE:
            return max(1, len(item.data) // max(1, item.element.element_size()))
        return 1

    # --- queueing -------------------------------------------------------------------------------
    def _ready(self, ratio: float, setting: str) -> None:
        arm = self.arm
        if not arm.servo:
            raise Flag(FLAG_NOT_READY, "the servo is off")
        if arm.alarms:
            raise Flag(FLAG_NOT_READY, "an alarm is active")
        if ratio <= 0:
            raise Flag(FLAG_NOT_READY, f"the speed is 0: set it with {setting}")

    def _room(self, count: int) -> bool:
        device = self.arm.device
        if count > device.capacity:
            raise Flag(FLAG_INVALID, f"{count} poses do not fit the motion queue "
                                     f"({device.capacity} motions)")
        return device.capacity - device.queue_length >= count

    @staticmethod
    def _submit(queue: Callable[[], dict]) -> None:
        try:
            queue()
        except Refused as r:
            raise refused_flag(r) from None

    def _queue_together(self, command: Callable[[], None]) -> bool:
        """Queue the motions `command` gives as one (a pose sequence, a grasp): all of them or,
        on a refusal of any, none. False when another client took the room `_room` saw (the
        program waits again; nothing was queued)."""
        try:
            with self.arm.all_or_nothing() as ids:
                command()
        except Refused as r:
            if r.code == ReturnCode.FULL_MOTION_QUEUE_ERR:
                return False
            raise refused_flag(r) from None
        for motion_id in ids:
            self._issued(motion_id)
        return True

    def _joint_move(self, goal_of: Callable[[ArmSetpoint], np.ndarray], label: str) -> None:
        self._submit(lambda: self.arm.queue_joint_move(goal_of, label, self.jspeed,
                                                        self._ramp("joint")))

    def _cartesian_move(self, path_of: Callable[[np.ndarray], LinePath], label: str,
                        psi: float | None) -> None:
        tool = self.tool
        self._submit(lambda: self.arm.queue_cartesian(
            lambda P0: InHand(path_of(P0 @ tool), tool), label, psi=psi,
            speed_ratio=self._cartesian_ratio(), ramp=self._ramp("cartesian")))

    def _ptp_to(self, target: Target, label: str) -> None:
        """Joint interpolation to a hand pose, in the pose's configuration and elbow angle."""
        arm, kin = self.arm, self.arm.kin
        hand = target.pose @ inverse(self.tool)
        psi = math.radians(target.elbow)
        lower, upper = np.radians(arm.soft_limit_joint[:, 0]), np.radians(arm.soft_limit_joint[:, 1])

        def goal_of(start: ArmSetpoint) -> np.ndarray:
            reference = configured(start.joints, target.configuration)
            flange = arm.frames.flange_of(hand)     # the frames in force while planning
            try:
                q = kin.solve(flange, reference, psi=psi, lower=lower, upper=upper)
            except Unreachable as e:
                raise value_error(f"{label}: {e}") from None
            if kin.flags(q) != target.configuration:
                raise value_error(f"{label}: the pose cannot be reached in configuration "
                                  f"{target.configuration} within the joint limits")
            return q
        self._joint_move(goal_of, label)

    def _line_to(self, target: Target, label: str) -> None:
        self._same_configuration(target)
        self._cartesian_move(lambda P0: LinePath(P0, target.pose), label,
                             math.radians(target.elbow))

    def _same_configuration(self, target: Target) -> None:
        q, _ = self._start()
        if self.arm.kin.flags(q) != target.configuration:
            raise Flag(FLAG_CONFIGURATION,
                       f"the pose has configuration {target.configuration}, the arm "
                       f"{self.arm.kin.flags(q)}: change it with a joint move first")

    def _gripper(self, opening_mm: float, label: str) -> None:
        ratio = 100.0 * opening_mm / self.max_opening
        self._submit(lambda: self.arm.queue_gripper(ratio, label))

    def _move(self, vm: VM, proc: Process, name: str, kinds: list[ArgKind],
              count: Callable[[list], int], run: Callable[[list], None], ratio: float,
              setting: str) -> object:
        """The frame of every motion command: its arguments (of `kinds`, deepest first) stay on
        the stack while the queue has no room for its motions (the program waits); then they
        are taken and the motions queued; the flag tells how it went."""
        args = _arguments(proc, kinds)
        nargs = len(args)
        try:
            self._ready(ratio, setting)
            if not self._room(count(args)) or not self._queue_together(lambda: run(args)):
                return vm.timed_wait(proc, math.inf, POLL)
        except Flag as flag:
            del proc.stack[len(proc.stack) - nargs:]
            proc.timed = None
            return self._flag(proc, name, flag)
        del proc.stack[len(proc.stack) - nargs:]
        proc.timed = None
        self._flag(proc, name, None)

    # === ED00–ED05: speeds and accelerations =====================================================
    def _setting(self, proc: Process, name: str, valid: Callable[[float], str | None],
                 apply: Callable[[float], None]) -> None:
        value = float(pop_num(proc).value)
        why = valid(value)
        if why is None:
            apply(value)
        self._flag(proc, name, None if why is None else Flag(FLAG_INVALID, why))

    @staticmethod
    def _within(low: float, high: float, unit: str,
                low_open: bool = False) -> Callable[[float], str | None]:
        def valid(value: float) -> str | None:
            if (value <= low if low_open else value < low) or value > high:
                bracket = "(" if low_open else "["
                return f"{value:g} {unit} is outside {bracket}{low:g}, {high:g}]"
            return None
        return valid

    def jspeed_(self, vm: VM, proc: Process) -> None:
        self._setting(proc, "JSPEED", self._within(0.0, 100.0, "%"),
                      lambda v: setattr(self, "jspeed", v))

    def speed_(self, vm: VM, proc: Process) -> None:
        self._setting(proc, "SPEED", self._within(0.0, self.arm.max_speed_cartesian[0], "mm/s"),
                      lambda v: setattr(self, "speed", v))

    def _accel_percent(self, proc: Process, name: str, attribute: str) -> None:
        self._setting(proc, name, self._within(0.0, 100.0, "%", low_open=True),
                      lambda v: setattr(self, attribute, ("percent", v)))

    def _accel_time(self, proc: Process, name: str, attribute: str) -> None:
        minimum = max(self.arm.min_accel_time_joint, self.arm.min_accel_time_cartesian)
        self._setting(proc, name, self._within(minimum, MAX_RAMP, "s"),
                      lambda v: setattr(self, attribute, ("time", v)))

    def accel1(self, vm: VM, proc: Process) -> None:
        self._accel_percent(proc, "ACCEL1", "accel")

    def accel2(self, vm: VM, proc: Process) -> None:
        self._accel_time(proc, "ACCEL2", "accel")

    def decel1(self, vm: VM, proc: Process) -> None:
        self._accel_percent(proc, "DECEL1", "decel")

    def decel2(self, vm: VM, proc: Process) -> None:
        self._accel_time(proc, "DECEL2", "decel")

    # === ED06–ED0B: configuration ===============================================================
    def sconf(self, vm: VM, proc: Process) -> None:
        vm.configuration = integer_value(pop_num(proc)) & CONFIGURATION_BITS
        _push_flag(proc, 0)

    def sconf2(self, vm: VM, proc: Process) -> None:
        """No extended configuration bits are defined for this arm: ignored."""
        pop_num(proc)
        _push_flag(proc, 0)

    def sconf3(self, vm: VM, proc: Process) -> None:
        """Number 1: the elbow (arm) angle in degrees that PNT gives; other numbers ignored."""
        value = float(pop_num(proc).value)
        number = integer_value(pop_num(proc))
        if number == 1:
            vm.elbow = math.remainder(value, 360.0)
        _push_flag(proc, 0)

    def gconf(self, vm: VM, proc: Process) -> None:
        proc.push(Num(I2, vm.configuration & CONFIGURATION_BITS))

    def gconf2(self, vm: VM, proc: Process) -> None:
        proc.push(Num(I2, 0))

    def gconf3(self, vm: VM, proc: Process) -> None:
        number = integer_value(pop_num(proc))
        proc.push(make_real(R8, vm.elbow) if number == 1 else Num(I2, 0))

    # === ED0C–ED10: current state, calibration, pause, delay =====================================
    def here(self, vm: VM, proc: Process) -> None:
        proc.push(self.hand_pose(self.arm.feedback_joints))

    def jhere(self, vm: VM, proc: Process) -> None:
        values = np.degrees(self.arm.feedback_joints)
        proc.push(Array(TagHead(R4), struct.pack(f">{len(values)}f", *values)))

    def calib(self, vm: VM, proc: Process) -> object:
        """A joint move to the home (calibration) position at the JSPEED, waited for; a refusal
        is an exception (CALIB has no flag)."""
        key = _wait_key(proc)
        motion_id = self._waits.get(key)
        if motion_id is None:
            try:
                self._ready(self.jspeed, "JSPEED")
                goal = np.radians(self.arm.home)
                if not self._queue_together(lambda: self._joint_move(lambda start: goal,
                                                                      "CALIB")):
                    proc.wake_at = self.now() + POLL      # another client took the room
                    return WAIT
            except Flag as flag:
                raise fail(K.ROBOT_ERROR, f"calibration move refused: {flag.reason}") from None
            motion_id = self._waits[key] = self.last_motion
        if not self.arm.device.is_over(motion_id):
            proc.wake_at = self.now() + POLL
            return WAIT
        del self._waits[key]
        return None

    def pause(self, vm: VM, proc: Process) -> None:
        """Shows the message, pauses the arm (it decelerates and holds, its queue kept) and
        waits until the arm is resumed (the resume service), then pushes 0."""
        message = pop_of(proc, Str, "a message (St)").data.decode("utf-8", "replace")
        self.console(f"PAUSE: {message}")
        arm = self.arm
        generation = arm.device.generation          # a stop (servo off, an alarm) changes it
        servo, alarms = arm.servo, {a.as_tuple() for a in arm.alarms}
        arm.device.pause(arm.current_ramp())
        self.state, self.message = "paused", _shown_line(message)
        started = self.now()
        try:
            while arm.device.paused:
                self.check(vm)
                self.sleep(POLL)
        finally:
            self._frozen += self.now() - started
            self._last_check = self.now()
            self.state, self.message = "running", ""
        servo_lost = servo and not arm.servo
        if (arm.device.generation != generation or servo_lost
                or any(a.as_tuple() not in alarms for a in arm.alarms)):
            # the pause ended by a stop meanwhile, not a resume: the program must not go on
            # moving (a servo already off or an alarm already there before it does not count)
            raise fail(K.SERVO_ERROR if servo_lost else K.ROBOT_ERROR,
                       "the arm was stopped while the program was paused (stop, servo off or "
                       "an alarm; only resume goes on)")
        _push_flag(proc, 0)

    def delay(self, vm: VM, proc: Process) -> object:
        """DELAY t (s): the count stands still while an interrupt action or a PAUSE runs."""
        seconds = float(_number(proc.peek()).value)   # stays on the stack while waiting
        if not 0.0 <= seconds <= MAX_DELAY:
            proc.pop()
            return self._flag(proc, "DELAY", Flag(FLAG_INVALID, f"{seconds:g} s is outside "
                                                                f"[0, {MAX_DELAY:g}] s"))
        key = _wait_key(proc)
        clock = self.now() if isinstance(proc.number, str) else self.now() - self._frozen
        end = self._waits.setdefault(key, clock + seconds)
        if clock >= end - 1e-9:
            del self._waits[key]
            proc.pop()
            return _push_flag(proc, 0)
        proc.wake_at = self.now() + (end - clock)
        return WAIT

    # === ED11–ED19: motions ======================================================================
    def _poses_move(self, vm: VM, proc: Process, name: str, relative: bool,
                    joint: bool) -> object:
        def run(args: list) -> None:
            targets = self._targets(args[0])
            if relative:
                _, start = self._start()
                targets = [Target(compose_relative(start.pose, t.pose), start.configuration,
                                  start.elbow + t.elbow) for t in targets]
            for target in targets:
                (self._ptp_to if joint else self._line_to)(target, name)
        if joint:
            return self._move(vm, proc, name, [POSES], lambda a: self._count_of(a[0]), run,
                              self.jspeed, "JSPEED")
        return self._move(vm, proc, name, [POSES], lambda a: self._count_of(a[0]), run,
                          self._cartesian_ratio(), "SPEED")

    def ajmove(self, vm: VM, proc: Process) -> object:
        return self._poses_move(vm, proc, "AJMOVE", relative=False, joint=True)

    def ijmove(self, vm: VM, proc: Process) -> object:
        return self._poses_move(vm, proc, "IJMOVE", relative=True, joint=True)

    def almove(self, vm: VM, proc: Process) -> object:
        return self._poses_move(vm, proc, "ALMOVE", relative=False, joint=False)

    def ilmove(self, vm: VM, proc: Process) -> object:
        return self._poses_move(vm, proc, "ILMOVE", relative=True, joint=False)

    def hmove(self, vm: VM, proc: Process) -> object:
        """Moves expressed in the hand's tool frame where the command starts: T_start · T(a)."""
        def run(args: list) -> None:
            _, start = self._start()
            for t in self._targets(args[0]):
                self._line_to(Target(start.pose @ t.pose, start.configuration,
                                     start.elbow + t.elbow), "HMOVE")
        return self._move(vm, proc, "HMOVE", [POSES], lambda a: self._count_of(a[0]), run,
                          self._cartesian_ratio(), "SPEED")

    def cmove1(self, vm: VM, proc: Process) -> object:
        """a b c d: plane a (1 xy, 2 yz, 3 zx), angle b (degree, ≥ 0 counter-clockwise seen
        from the plane's normal axis), centre c (its position, moved into the plane through
        the start), orientation d (1 turns with the arc, 2 kept, 3 ends at c's)."""
        def run(args: list) -> None:
            plane, angle, centre_pose, orient = args
            plane, orient = integer_value(plane), integer_value(orient)
            sweep = math.radians(float(angle.value))
            centre = self.target_of(centre_pose)
            if plane not in PLANES or orient not in (1, 2, 3):
                raise Flag(FLAG_INVALID, f"plane {plane} (1–3) or orientation {orient} (1–3)")
            if not abs(sweep) < 2 * math.pi:
                raise Flag(FLAG_INVALID, f"the angle must be within (−360, 360)°")
            _, start = self._start()
            axis = np.zeros(3)
            axis[PLANES[plane]] = 1.0
            p0 = start.pose[:3, 3]
            c = centre.pose[:3, 3].copy()
            c[PLANES[plane]] = p0[PLANES[plane]]
            radius = float(np.linalg.norm(p0 - c))
            if radius < 1e-6:
                raise Flag(FLAG_INVALID, "the start is the centre of the arc")
            end = np.eye(4)
            end[:3, 3] = c + rotate_about(axis, sweep) @ (p0 - c)
            end[:3, :3] = {1: rotate_about(axis, sweep) @ start.pose[:3, :3],
                           2: start.pose[:3, :3], 3: centre.pose[:3, :3]}[orient]
            if radius * 1000.0 > ARC_RADIUS_LIMIT or sweep == 0.0:
                self._cartesian_move(lambda P0: LinePath(P0, end), "CMOVE1", None)
            else:
                self._cartesian_move(lambda P0: CirclePath(P0, c, axis, sweep, end, orient == 1),
                                     "CMOVE1", None)
        return self._move(vm, proc, "CMOVE1", [NUMBER, NUMBER, A_POSE, NUMBER], lambda a: 1, run,
                          self._cartesian_ratio(), "SPEED")

    def cmove3(self, vm: VM, proc: Process) -> object:
        """a b: the arc from the start through a's position to b (b's orientation and elbow)."""
        def run(args: list) -> None:
            via, target = (self.target_of(item) for item in args)
            self._same_configuration(target)
            _, start = self._start()
            b = via.pose[:3, 3]
            try:
                arc = ArcPath(start.pose, b, target.pose)
            except ValueError as e:
                raise Flag(FLAG_INVALID, str(e)) from None
            if arc.radius * 1000.0 > ARC_RADIUS_LIMIT:
                self._cartesian_move(lambda P0: LinePath(P0, target.pose), "CMOVE3",
                                     math.radians(target.elbow))
            else:
                self._cartesian_move(lambda P0: ArcPath(P0, b, target.pose), "CMOVE3",
                                     math.radians(target.elbow))
        return self._move(vm, proc, "CMOVE3", [A_POSE, A_POSE], lambda a: 1, run,
                          self._cartesian_ratio(), "SPEED")

    def _joints_of(self, item: Array) -> np.ndarray:
        values = np.array([float(v.value) for v in array_elements(item)])
        if len(values) != self.arm.axis_count:
            raise Flag(FLAG_INVALID, f"{len(values)} joint values, the arm has "
                                     f"{self.arm.axis_count}")
        return np.radians(values)

    def adrive(self, vm: VM, proc: Process) -> object:
        def run(args: list) -> None:
            goal = self._joints_of(args[0])
            self._joint_move(lambda start: goal, "ADRIVE")
        return self._move(vm, proc, "ADRIVE", [JOINTS], lambda a: 1, run, self.jspeed, "JSPEED")

    def idrive(self, vm: VM, proc: Process) -> object:
        def run(args: list) -> None:
            delta = self._joints_of(args[0])
            self._joint_move(lambda start: start.joints + delta, "IDRIVE")
        return self._move(vm, proc, "IDRIVE", [JOINTS], lambda a: 1, run, self.jspeed, "JSPEED")

    # === ED1A–ED1D: approach accuracy, completion ================================================
    def sacc(self, vm: VM, proc: Process) -> None:
        self._setting(proc, "SACC", self._within(0.0, MAX_ACCURACY, "mm"),
                      lambda v: setattr(self, "accuracy", v))

    def gacc(self, vm: VM, proc: Process) -> None:
        proc.push(make_real(R4, self.accuracy))

    def wait(self, vm: VM, proc: Process) -> object:
        """$WAIT t: t s at most (t < 0: no limit, 0: look once); 0 over, 1/2/3 still moving
        (robot / hand / both) when the time ran out, < 0 an abnormal end."""
        seconds = float(_number(proc.peek()).value)
        status = self.motion_status()
        if status > 0:
            limit = math.inf if seconds < 0 else seconds
            if self._vm_wait(vm, proc, limit) is WAIT:
                return WAIT
        proc.pop()
        proc.timed = None
        _push_flag(proc, status)

    def _vm_wait(self, vm: VM, proc: Process, seconds: float) -> object:
        return vm.timed_wait(proc, seconds, POLL)

    def done(self, vm: VM, proc: Process) -> None:
        """$DONE; while something moves it lets one control cycle pass (a program that polls
        $DONE in a loop does not keep the processor from the simulation)."""
        status = self.motion_status()
        if status > 0:
            self.sleep(0.0)
        _push_flag(proc, status)

    # === ED1E–ED23: hands ========================================================================
    def _hand(self) -> Hand:
        hand = self.hands.get(self.hand)
        if hand is None:
            raise Flag(FLAG_HAND, f"hand {self.hand} is not defined")
        return hand

    def _hand_motion(self, vm: VM, proc: Process, name: str,
                     opening: Callable[[Hand], float]) -> object:
        try:
            self._ready(1.0, "")
            if not self._room(1) or not self._queue_together(
                    lambda: self._gripper(opening(self._hand()), name)):
                return self._vm_wait(vm, proc, math.inf)
        except Flag as flag:
            kind = K.SERVO_ERROR if not self.arm.servo else K.ROBOT_ERROR
            raise fail(kind, f"{name}: {flag.reason}") from None
        proc.timed = None
        return None

    def handopen(self, vm: VM, proc: Process) -> object:
        return self._hand_motion(vm, proc, "HANDOPEN", lambda h: self.max_opening
                                 if h.open_mm is None else h.open_mm)

    def handclose(self, vm: VM, proc: Process) -> object:
        return self._hand_motion(vm, proc, "HANDCLOSE", lambda h: h.close_mm)

    def grasp(self, vm: VM, proc: Process) -> object:
        """a1 1 GRASP: the opening a1 (mm) of the gripper."""
        count = integer_value(_number(proc.peek()))

        def run(args: list) -> None:
            params = args[:-1]
            self._hand()
            if count != 1:
                raise Flag(FLAG_INVALID, f"the gripper takes 1 parameter (opening, mm), "
                                         f"not {count}")
            opening = float(params[0].value)
            if not 0.0 <= opening <= self.max_opening:
                raise Flag(FLAG_INVALID, f"opening {opening:g} mm is outside "
                                         f"[0, {self.max_opening:g}] mm")
            self._gripper(opening, "GRASP")
        if count < 0:
            proc.pop()
            return self._flag(proc, "GRASP", Flag(FLAG_INVALID, f"parameter count {count}"))
        kinds = [NUMBER] * (min(count, len(proc.stack)) + 1)   # past the stack: underflow
        return self._move(vm, proc, "GRASP", kinds, lambda a: 1, run, 1.0, "")

    def handdef(self, vm: VM, proc: Process) -> None:
        """a1 … an n b: hand b; parameters (all optional, in this order): the tool frame (Trn,
        mm, seen from the control point), the HANDOPEN and HANDCLOSE openings (mm)."""
        number = integer_value(_number(proc.pop()))
        count = integer_value(_number(proc.pop()))
        params = tuple(pop_many(proc, count))
        try:
            hand = self._hand_of(params)
            if not 1 <= number <= MAX_HAND_NUMBER:
                raise Flag(FLAG_INVALID, f"hand number {number} is outside 1–{MAX_HAND_NUMBER}")
            if number not in self.hands and len(self.hands) >= MAX_HANDS:
                raise Flag(FLAG_HAND, f"{MAX_HANDS} hands are defined already")
        except Flag as flag:
            return self._flag(proc, "HANDDEF", flag)
        self.hands[number] = hand
        self._flag(proc, "HANDDEF", None)

    def _hand_of(self, params: tuple) -> Hand:
        if len(params) > 3:
            raise Flag(FLAG_INVALID, f"{len(params)} parameters: at most 3 (tool frame, "
                                     "open and close openings)")
        hand = Hand(params)
        if params:
            if not isinstance(params[0], Trn):
                raise Flag(FLAG_INVALID, "the first parameter is the tool frame (Trn)")
            matrix = matrix_of(params[0])
            try:
                hand.tool = hg_to_pose([float(x) for x in matrix[:3, :4].reshape(-1)], "tool")
            except Refused as r:
                raise Flag(FLAG_INVALID, r.comment) from None
        openings = []
        for item in params[1:]:
            if not isinstance(item, Num) or not 0.0 <= float(item.value) <= self.max_opening:
                raise Flag(FLAG_INVALID, f"an opening is a number of 0 … {self.max_opening:g} mm")
            openings.append(float(item.value))
        if openings:
            hand.open_mm = openings[0]
        if len(openings) > 1:
            hand.close_mm = openings[1]
        return hand

    def handref(self, vm: VM, proc: Process) -> None:
        hand = self.hands.get(integer_value(_number(proc.pop())))
        if hand is None:
            proc.push(Num(I2, -1))
            return
        proc.stack.extend(hand.params)
        proc.push(Num(I2, len(hand.params)))

    def handchg(self, vm: VM, proc: Process) -> None:
        number = integer_value(_number(proc.pop()))
        if number not in self.hands:
            return self._flag(proc, "HANDCHG", Flag(FLAG_HAND, f"hand {number} is not defined"))
        self.hand = number
        self._flag(proc, "HANDCHG", None)


def configured(q: np.ndarray, configuration: int) -> np.ndarray:
    """A reference posture with the signs of θ2, θ4, θ6 of `configuration` (kinematics flags:
    bit 0 θ2 < 0, bit 1 θ4 > 0, bit 2 θ6 < 0) and clear of zero, so that IK takes that branch."""
    ref = np.array(q, float)
    for bit, axis, negative_when_set in ((1, 1, True), (2, 3, False), (4, 5, True)):
        negative = bool(configuration & bit) == negative_when_set
        ref[axis] = (-1.0 if negative else 1.0) * max(abs(ref[axis]), 0.3)
    return ref


def _number(item: object) -> Num:
    if not isinstance(item, Num):
        raise fail(K.TYPE_MISMATCH, "a number expected")
    return item


# the types of a motion command's arguments: a test and what the error message calls it
ArgKind = tuple[Callable[[object], bool], str]
NUMBER: ArgKind = (lambda v: isinstance(v, Num), "a number")
A_POSE: ArgKind = (lambda v: isinstance(v, Pose), "a pose (Pm)")
POSES: ArgKind = (lambda v: isinstance(v, Pose) or isinstance(v, Array) and v.element.tag == POSE,
                  "a pose (Pm) or a pose sequence (Ar of Pm)")
JOINTS: ArgKind = (lambda v: isinstance(v, Array) and v.element.tag in NUMERIC_TAGS,
                   "an array of numbers (the joint values)")


def _arguments(proc: Process, kinds: list[ArgKind]) -> list:
    """A command's arguments (deepest first), left on the stack: taken from the top down and
    checked as taken, so that a wrong type is the exception (Annex 1 §9) before any flag
    (the arm not ready was flag 4 for a string given as a pose)."""
    args = []
    for depth, (fits, what) in enumerate(reversed(kinds)):
        item = proc.peek(depth)
        if not fits(item):
            raise fail(K.TYPE_MISMATCH, f"{what} expected, got {type_name(item)}")
        args.append(item)
    return args[::-1]


FUNCTIONS: dict[str, Handler] = {
    "JSPEED": RobotHost.jspeed_, "SPEED": RobotHost.speed_,
    "ACCEL1": RobotHost.accel1, "ACCEL2": RobotHost.accel2,
    "DECEL1": RobotHost.decel1, "DECEL2": RobotHost.decel2,
    "SCONF": RobotHost.sconf, "SCONF2": RobotHost.sconf2, "SCONF3": RobotHost.sconf3,
    "GCONF": RobotHost.gconf, "GCONF2": RobotHost.gconf2, "GCONF3": RobotHost.gconf3,
    "HERE": RobotHost.here, "JHERE": RobotHost.jhere, "CALIB": RobotHost.calib,
    "PAUSE": RobotHost.pause, "DELAY": RobotHost.delay,
    "AJMOVE": RobotHost.ajmove, "IJMOVE": RobotHost.ijmove, "ALMOVE": RobotHost.almove,
    "ILMOVE": RobotHost.ilmove, "HMOVE": RobotHost.hmove, "CMOVE1": RobotHost.cmove1,
    "CMOVE3": RobotHost.cmove3, "ADRIVE": RobotHost.adrive, "IDRIVE": RobotHost.idrive,
    "SACC": RobotHost.sacc, "GACC": RobotHost.gacc, "$WAIT": RobotHost.wait,
    "$DONE": RobotHost.done, "HANDOPEN": RobotHost.handopen, "HANDCLOSE": RobotHost.handclose,
    "GRASP": RobotHost.grasp, "HANDDEF": RobotHost.handdef, "HANDREF": RobotHost.handref,
    "HANDCHG": RobotHost.handchg,
}
