"""Waiting in action goals without holding an executor thread, shared by both nodes' servers.

A goal's execute callback is a coroutine on the motion plane's executor. It awaits a `Watch`:
the watch settles the wait when its condition holds, checked whenever something pokes it (a
device retiring a motion, a program ending, a cancel request: any thread) and on a periodic
tick that also publishes feedback. Any number of goals wait on one thread, so the bound
(`GoalSlots`) only limits what the process keeps track of; a goal beyond it is rejected.
`wait_for_motion` is the ~/wait_motion of either device; each node writes its own reply style.
"""
from __future__ import annotations

import math
import threading
import time
from dataclasses import dataclass
from typing import Any, Awaitable, Callable, Generic, Iterable, TypeVar

from rclpy.action import CancelResponse, GoalResponse
from rclpy.node import Node
from rclpy.task import Future

from acti_bringup.serving.adapter import Plane
from acti_bringup.serving.spinning import steady_timer
from acti_motion.executor import Device

T = TypeVar("T")
SHUTDOWN = "the node shuts down: send the goal again once it is back"
GOALS_END_S = 3.0       # the longest wait for the goals to end (a program's: the arm at rest)
RESULTS_SENT_S = 0.2    # for the goal plane to send the results, and DDS to deliver them


class GoalSlots:
    """At most `limit` goals of the servers that share it run at once; more are rejected."""

    def __init__(self, node: Node, limit: int, parameter: str) -> None:
        if limit < 1:
            raise ValueError(f"{parameter} must be >= 1")
        self._node, self._parameter = node, parameter
        self._slots = threading.BoundedSemaphore(limit)

    def admit(self, _goal: Any) -> GoalResponse:
        if self._slots.acquire(blocking=False):
            return GoalResponse.ACCEPT
        self._node.get_logger().warning(f"rejected an action goal: {self._parameter} running")
        return GoalResponse.REJECT

    def holding(self, execute: Callable[[Any], Awaitable[Any]]) -> Callable[[Any], Awaitable[Any]]:
        """`execute` that gives its slot back however it ends."""
        async def run(goal_handle: Any) -> Any:
            try:
                return await execute(goal_handle)
            finally:
                self._slots.release()
        return run


@dataclass
class _Wait(Generic[T]):
    outcome: Callable[[], T | None]
    feedback: Callable[[], None]
    future: Future
    closed: Callable[[str], T] | None


class Watch:
    """Settles awaited conditions on the thread of the executor that serves `node`."""

    def __init__(self, node: Node, period: float) -> None:
        self._waits: list[_Wait] = []
        self._guard = node.create_guard_condition(self._settle)
        self._timer = steady_timer(node, period, self._tick)
        self._timer.cancel()                     # ticks only while something waits
        self._closing = node.context.ok
        self._closed: str | None = None

    def poke(self) -> None:
        """Re-check the conditions soon (any thread; cheap and non-blocking); nothing while
        nothing waits (`until` adds a wait before its first check, so no poke is missed). A
        0° move's accept on an idle arm retires it at once, and the three watches' triggers
        woke the serving thread of the goals beside the answer: 2.4 times the same-type bare
        node's round trip."""
        if not self._waits:
            return
        try:
            self._guard.trigger()
        except Exception:
            if self._closing():                 # gone with the node at shutdown: nothing waits
                raise

    async def until(self, outcome: Callable[[], T | None], feedback: Callable[[], None],
                    closed: Callable[[str], T] | None = None) -> T:
        """Wait until `outcome()` is not None (checked on pokes and ticks), calling `feedback()`
        every tick meanwhile; its value. Once the watch is closed, `closed(why)` instead, if
        given (else the wait goes on: something else ends it)."""
        wait = _Wait(outcome, feedback, Future(), closed)
        self._waits.append(wait)        # first: a poke from now on sees that something waits
        try:
            now = self._check(wait)
        except BaseException:
            self._waits.remove(wait)
            raise
        if now is not None:
            self._waits.remove(wait)
            return now
        if self._timer.is_canceled():
            self._timer.reset()
        return await wait.future

    def close(self, why: str) -> None:
        """The node stops: every wait that can end so ends now with `closed(why)` (any thread),
        so that the goals held are answered before the process goes."""
        self._closed = why
        self.poke()

    @property
    def idle(self) -> bool:
        """Nothing waits."""
        return not self._waits

    def _check(self, wait: _Wait) -> Any:
        if self._closed is not None and wait.closed is not None:
            return wait.closed(self._closed)
        return wait.outcome()

    def _settle(self) -> list[_Wait]:
        pending = []
        for wait in self._waits:
            now = self._check(wait)
            if now is None:
                pending.append(wait)
            else:
                wait.future.set_result(now)
        self._waits = pending
        if not pending:
            self._timer.cancel()
        return pending

    def _tick(self) -> None:
        for wait in self._settle():
            wait.feedback()


def end_goals(planes: Iterable[Plane], why: str = SHUTDOWN) -> None:
    """End every goal the planes' action servers hold, and give their results time to reach
    the clients: a goal that dies with the process unanswered keeps its client waiting for
    ever (rclcpp ends a goal handle destroyed unfinished; rclpy does not). Before the
    simulation stops, so that a program's run ends with the arm at rest."""
    ends = [end for plane in planes for end in plane.goal_ends]
    if all(end.idle for end in ends):
        return
    for end in ends:
        end.close(why)
    deadline = time.monotonic() + GOALS_END_S
    while not all(end.idle for end in ends) and time.monotonic() < deadline:
        time.sleep(0.01)
    time.sleep(RESULTS_SENT_S)


def accept_cancel(watch: Watch) -> Callable[[Any], CancelResponse]:
    """A cancel callback that lets the waiting goal see the request at once."""
    def cancel(_goal: Any) -> CancelResponse:
        watch.poke()
        return CancelResponse.ACCEPT
    return cancel


def device_watch(node: Node, device: Device, period: float) -> Watch:
    """A watch poked whenever `device` retires a motion."""
    watch = Watch(node, period)
    device.on_retire(watch.poke)
    return watch


def timeout_error(timeout: float) -> str | None:
    """Why a goal's `timeout` (s, 0: none) is refused, or None."""
    if not math.isfinite(timeout) or timeout < 0:
        return f"timeout is {timeout:g} s: it must be a finite number of seconds >= 0 (0: no limit)"
    return None


@dataclass(frozen=True)
class WaitOutcome:
    """How a wait ended: `end` names the goal handle's method that ends the goal (succeed,
    abort, canceled); `bad_goal` marks a goal refused before waiting; `message` says why."""
    motion_id: int
    end: str
    completed: bool = False
    bad_goal: bool = False
    message: str = ""

    @property
    def aborted(self) -> bool:
        return self.end == "abort"

    def finish(self, goal_handle: Any) -> None:
        getattr(goal_handle, self.end)()


Feedback = Callable[[int, str, float, int], None]


async def wait_for_motion(goal_handle: Any, device: Device, watch: Watch,
                          feedback: Feedback) -> WaitOutcome:
    """Wait for goal.motion_id (0: everything queued now) with goal.timeout (0: no limit),
    calling feedback(current id, label, progress, queue length) every tick of `watch`."""
    goal = goal_handle.request
    target = goal.motion_id or device.last_id
    refused = timeout_error(goal.timeout)
    if refused:
        return WaitOutcome(target, "abort", bad_goal=True, message=refused)
    if goal.motion_id > device.last_id:
        return WaitOutcome(target, "abort", bad_goal=True,
                           message=f"motion {goal.motion_id} was never queued "
                                   f"(the last is {device.last_id})")
    deadline = time.monotonic() + goal.timeout if goal.timeout > 0 else math.inf

    def outcome() -> WaitOutcome | None:
        if device.is_over(target):
            why = device.discard_reason(target)
            return WaitOutcome(target, "succeed", why is None,
                               message="" if why is None else f"discarded: {why}")
        if goal_handle.is_cancel_requested:
            return WaitOutcome(target, "canceled", message="canceled: the motion goes on")
        if time.monotonic() >= deadline:
            return WaitOutcome(target, "abort", message=f"timed out after {goal.timeout:g} s")
        return None
    # the deadline pokes the watch itself: checked on the feedback tick alone, a timeout was
    # answered up to a feedback period late (0.01 s: 0.106 s). A timer cannot wait longer than
    # TIMEOUT_MAX (~292 years; beyond, it dies of OverflowError): the tick checks such a deadline.
    timed = 0 < goal.timeout <= threading.TIMEOUT_MAX
    alarm = threading.Timer(goal.timeout, watch.poke) if timed else None
    if alarm is not None:
        alarm.daemon = True
        alarm.start()
    try:
        return await watch.until(outcome, lambda: feedback(*device.status()),
                                 closed=lambda why: WaitOutcome(target, "abort", message=why))
    finally:
        if alarm is not None:
            alarm.cancel()
