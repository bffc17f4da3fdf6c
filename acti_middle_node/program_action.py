"""~/run_program (acti_msgs/action/RunProgram): a STROLIC program run on the arm, with its
progress as feedback; canceling stops the program and the arm.

The program runs on a thread of its own (`acti_motion.programs.run.ProgramRun`), never on the
executor's threads, which go on serving stop, pause, resume and get_state meanwhile; the goal's
callback only publishes feedback and waits for the end. One program runs at a time. The robot's
digital I/O (`RobotIO`) lives as long as the node: outputs keep their values from run to run.
"""
from __future__ import annotations

import dataclasses
import threading
from typing import Any

from acti_msgs.action import RunProgram
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.node import Node

from acti_bringup.conversions import fill
from acti_motion.arm.core import ArmCore
from acti_motion.programs.run import ProgramRun, Status
from acti_motion.programs.robot import ProgramDefaults, RobotIO
from strolic.errors import StrolicError


class ProgramAction:
    """~/run_program of one ArmCore."""

    def __init__(self, node: Node, core: ArmCore, group: Any, feedback_rate_hz: float,
                 defaults: ProgramDefaults) -> None:
        self.node, self.core, self.defaults = node, core, defaults
        self.period = 1.0 / feedback_rate_hz
        self.io = RobotIO()
        self._busy = False
        self._current: ProgramRun | None = None
        self._lock = threading.Lock()
        self.server = ActionServer(node, RunProgram, "~/run_program", self._execute,
                                   callback_group=group, goal_callback=self._admit,
                                   cancel_callback=self._cancel)
        # the node stops: so does the run. A method: rclpy calls what a plain function returns
        node.context.on_shutdown(self._on_shutdown)

    def _admit(self, _goal: Any) -> GoalResponse:
        with self._lock:
            if self._busy:
                self.node.get_logger().warning("rejected a program: another one is running")
                return GoalResponse.REJECT
            self._busy = True
            return GoalResponse.ACCEPT

    def _on_shutdown(self) -> None:
        self._cancel(None)

    def _cancel(self, _goal: Any) -> CancelResponse:
        """At once: the program's waits end and the arm starts to decelerate now."""
        run = self._current
        if run is not None:
            run.cancel()
        return CancelResponse.ACCEPT

    def _execute(self, goal_handle: Any) -> RunProgram.Result:
        try:
            return self._run(goal_handle)
        finally:
            with self._lock:
                self._busy = False
                self._current = None

    def _run(self, goal_handle: Any) -> RunProgram.Result:
        goal = goal_handle.request
        program = bytes(goal.code) if len(goal.code) else goal.text
        try:
            run = ProgramRun(self.core, program, io=self.io, defaults=self.defaults,
                             budget=goal.budget or None)
        except StrolicError as error:
            goal_handle.abort()
            return RunProgram.Result(status=Status.INVALID, exception=error.report(),
                                     exception_kind=error.kind.value,
                                     exception_offset=_offset(error))
        self._current = run
        run.start()
        while not run.join(self.period):
            if goal_handle.is_cancel_requested or not self.node.context.ok():
                run.cancel()
            feedback = RunProgram.Feedback()
            fill(feedback, dataclasses.asdict(run.progress()))
            self._quietly_at_shutdown(goal_handle.publish_feedback, feedback)
        r = run.result
        error = r.error
        self.node.get_logger().info(f"program {r.status.name.lower()} after {r.instructions} "
                                    f"instructions, {r.duration:.2f} s {r.report}")
        result = RunProgram.Result(
            status=int(r.status), exception=r.report,
            exception_kind=error.kind.value if error else "",
            exception_offset=_offset(error), stack=r.stack, output=r.output,
            console=r.console, instructions=r.instructions, duration=r.duration)
        end = {Status.FINISHED: goal_handle.succeed, Status.CANCELED: goal_handle.canceled}
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
