"""~/run_program (acti_msgs/action/RunProgram): a STROLIC program run on the arm, with its
progress as feedback; canceling stops the program and the arm.

The program runs on a thread of its own (`acti_motion.programs.run.ProgramRun`), never on an
executor's thread; the goal's coroutine awaits its end on the goal plane without holding that
thread (`acti_bringup.serving.waiting.Watch`) and publishes feedback meanwhile, while the control plane
serves stop, pause, resume and get_state. One program runs at a time. The robot's
digital I/O (`RobotIO`) lives as long as the node: outputs keep their values from run to run.
"""
from __future__ import annotations

import dataclasses
import threading
from typing import Any

from acti_msgs.action import RunProgram
from rclpy.action import CancelResponse, GoalResponse

from acti_bringup.serving.adapter import Plane, action_server
from acti_bringup.serving.conversions import fill
from acti_bringup.serving.waiting import Watch
from acti_motion.arm.core import ArmCore
from acti_motion.programs.run import ProgramRun, Status
from acti_motion.programs.robot import ProgramDefaults, RobotIO
from strolic.errors import StrolicError


class ProgramAction:
    """~/run_program of one ArmCore."""

    def __init__(self, plane: Plane, core: ArmCore, feedback_rate_hz: float,
                 defaults: ProgramDefaults) -> None:
        self.node, self.core, self.defaults = plane.owner, core, defaults
        self.watch = Watch(plane, 1.0 / feedback_rate_hz)
        self.io = RobotIO()
        self._busy = False
        self._current: ProgramRun | None = None
        self._closed = ""
        self._lock = threading.Lock()
        self.server = action_server(plane, RunProgram, plane.name("run_program"), self._execute,
                                   goal_callback=self._admit, cancel_callback=self._cancel)
        # the node stops: so does the run. A method returning None: rclpy calls what the
        # callback returns, so a lambda returning a CancelResponse crashed the shutdown
        plane.context.on_shutdown(self._cancel_run)
        plane.goal_ends.append(self)

    def close(self, why: str) -> None:
        """The process stops: the run is canceled, and its goal ends (aborted, saying `why`)
        once the arm is at rest."""
        self._closed = why
        self._cancel_run()

    @property
    def idle(self) -> bool:
        return not self._busy

    def _admit(self, _goal: Any) -> GoalResponse:
        with self._lock:
            if self._busy:
                self.node.get_logger().warning("rejected a program: another one is running")
                return GoalResponse.REJECT
            self._busy = True
            return GoalResponse.ACCEPT

    def _cancel(self, _goal: Any) -> CancelResponse:
        """At once: the program's waits end and the arm starts to decelerate now."""
        self._cancel_run()
        return CancelResponse.ACCEPT

    def _cancel_run(self) -> None:
        run = self._current
        if run is not None:
            run.cancel()

    async def _execute(self, goal_handle: Any) -> RunProgram.Result:
        try:
            return await self._run(goal_handle)
        finally:
            with self._lock:
                self._busy = False
                self._current = None

    async def _run(self, goal_handle: Any) -> RunProgram.Result:
        goal = goal_handle.request
        program = bytes(goal.code) if len(goal.code) else goal.text
        run = ProgramRun(self.core, program, io=self.io, defaults=self.defaults,
                         budget=goal.budget or None)       # loaded on the run's thread
        self._current = run
        run.start()
        # the run's end pokes the watch from a thread that only waits for it
        threading.Thread(target=lambda: (run.join(), self.watch.poke()), name="program-end",
                         daemon=True).start()

        def feedback() -> None:
            msg = RunProgram.Feedback()
            fill(msg, dataclasses.asdict(run.progress()))
            self._quietly_at_shutdown(goal_handle.publish_feedback, msg)
        await self.watch.until(lambda: True if run.join(0) else None, feedback)
        r = run.result
        error = r.error
        self.node.get_logger().info(f"program {r.status.name.lower()} after {r.instructions} "
                                    f"instructions, {r.duration:.2f} s {r.report}")
        result = RunProgram.Result(
            status=int(r.status), exception=r.report,
            exception_kind=error.kind.value if error else "",
            exception_offset=_offset(error), stack=r.stack, output=r.output,
            console=r.console, instructions=r.instructions, duration=r.duration)
        end = {Status.FINISHED: goal_handle.succeed}
        if goal_handle.is_cancel_requested:     # else canceled by the process's stop (`close`)
            end[Status.CANCELED] = goal_handle.canceled
        elif self._closed:
            result.exception = f"{r.report} ({self._closed})"
        self._quietly_at_shutdown(end.get(r.status, goal_handle.abort))
        return result

    def _quietly_at_shutdown(self, fn, *args) -> None:
        """Call fn; once the node shuts down (the action server is going), a failure is none."""
        try:
            fn(*args)
        except Exception:
            if self.node.context.ok():
                raise


def _offset(error: StrolicError | None) -> int:
    return -1 if error is None or error.offset is None else error.offset
