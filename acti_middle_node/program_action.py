"""~/run_program (acti_msgs/action/RunProgram): a STROLIC program run on the arm, with its
progress as feedback; canceling stops the program and the arm.

The program runs on a thread of its own (`acti_motion.programs.run.ProgramRun`), never on an
executor's thread; the goal's coroutine awaits its end on the goal plane without holding that
thread (`acti_bringup.serving.waiting.Watch`) and publishes feedback meanwhile, while the control plane
serves stop, pause, resume and get_state. One program runs at a time. The robot's
digital I/O (`RobotIO`) lives as long as the node: outputs keep their values from run to run.

A RoboLine program (the goal's `source` and `points`) runs with its source map: feedback and the
exception name source lines; ~/program_debug (breakpoints, step, continue) and
~/program_variable (a variable by name) act on it while it runs, on the control plane: they only
set flags or read values. ~/check_program runs a program against a fresh arm in simulated time
(`acti_motion.programs.check`) on the goal plane: for its seconds, the feedback of a running
program waits, the control plane does not.
"""
from __future__ import annotations

import dataclasses
import threading
from typing import Any

from acti_msgs.action import RunProgram
from acti_msgs.msg import CheckedMove
from acti_msgs.srv import CheckProgram, ProgramDebug, ProgramVariable
from rclpy.action import CancelResponse, GoalResponse

from acti_bringup.serving.adapter import SERVICE_QOS, Plane, action_server
from acti_bringup.serving.conversions import fill
from acti_bringup.serving.waiting import Watch
from acti_motion.arm.core import ArmCore
from acti_view.program import ProgramShown
from acti_motion.programs.check import check_program
from acti_motion.programs.run import MAX_PROGRAM, ProgramRun, Status
from acti_motion.programs.robot import ProgramDefaults, RobotIO
from roboline import Program, Source, SourceError, compile_source, parse_points
from strolic.errors import ExceptionKind as K, StrolicError


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
        node = self.node
        node.create_service(ProgramDebug, "~/program_debug", self._debug, qos_profile=SERVICE_QOS)
        node.create_service(ProgramVariable, "~/program_variable", self._variable,
                            qos_profile=SERVICE_QOS)
        plane.create_service(CheckProgram, plane.name("check_program"), self._check,
                             qos_profile=SERVICE_QOS)

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

    def shown(self) -> ProgramShown | None:
        """The RoboLine program that runs, where it stands and its breakpoints (the live view)."""
        run = self._current
        if run is None or run.debugger is None:
            return None
        debugger = run.debugger
        return ProgramShown(run.source, debugger.line, sorted(debugger.breakpoints),
                            run.host.state)

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
        if len(goal.code) or goal.text or not goal.source:
            program = bytes(goal.code) if len(goal.code) else goal.text
        else:
            try:
                program = compiled(goal.source, goal.source_name, goal.points)
            except SourceError as error:
                return self._invalid(goal_handle, error)
        run = ProgramRun(self.core, program, io=self.io, defaults=self.defaults,
                         budget=goal.budget or None, breakpoints=goal.breakpoints,
                         stepping=goal.step)                # loaded on the run's thread
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
            exception_offset=_offset(error), exception_line=r.line, stack=r.stack,
            output=r.output,
            console=r.console, instructions=r.instructions, duration=r.duration)
        end = {Status.FINISHED: goal_handle.succeed}
        if goal_handle.is_cancel_requested:     # else canceled by the process's stop (`close`)
            end[Status.CANCELED] = goal_handle.canceled
        elif self._closed:
            result.exception = f"{r.report} ({self._closed})"
        self._quietly_at_shutdown(end.get(r.status, goal_handle.abort))
        return result

    def _invalid(self, goal_handle: Any, error: SourceError) -> RunProgram.Result:
        """A RoboLine program that does not compile: nothing ran."""
        self.node.get_logger().info(f"program invalid: {error.report()}")
        self._quietly_at_shutdown(goal_handle.abort)
        return RunProgram.Result(status=int(Status.INVALID), exception=error.report(),
                                 exception_kind=K.INVALID_CODE.value, exception_offset=-1,
                                 exception_line=error.line)

    # --- debugging the program that runs: the control plane (flags and reads only) ----------
    def _debug(self, request: ProgramDebug.Request,
               response: ProgramDebug.Response) -> ProgramDebug.Response:
        run = self._current
        debugger = run.debugger if run is not None else None
        if debugger is None:
            response.message = "no RoboLine program runs"
            return response
        command = request.command
        message = ""
        if command == ProgramDebug.Request.SET:
            message = debugger.set(request.lines)
        elif command == ProgramDebug.Request.CLEAR:
            debugger.clear(request.lines)
        elif command == ProgramDebug.Request.STEP:
            debugger.step()
        elif command == ProgramDebug.Request.CONTINUE:
            debugger.resume()
        else:
            message = f"unknown command {command} (SET 0, CLEAR 1, STEP 2, CONTINUE 3)"
        response.success, response.message = not message, message
        response.breakpoints = sorted(debugger.breakpoints)
        response.line, response.state = debugger.line, run.host.state
        return response

    def _variable(self, request: ProgramVariable.Request,
                  response: ProgramVariable.Response) -> ProgramVariable.Response:
        run = self._current
        if run is None:
            response.message = "no program runs"
            return response
        try:
            response.type, response.value = run.variable(request.name)
            response.success = True
        except KeyError as error:
            response.message = str(error.args[0])
        return response

    # --- check before motion: on the goal plane (seconds of simulation; never the control plane)
    def _check(self, request: CheckProgram.Request,
               response: CheckProgram.Response) -> CheckProgram.Response:
        try:
            program = compiled(request.source, request.source_name, request.points)
            result = check_program(program, self.core, self.defaults, request.budget or 600.0)
        except SourceError as error:
            response.message = error.report()
            return response
        except Exception as e:          # a bug or the world going away: an answer
            response.message = f"the check failed: {type(e).__name__}: {e}"
            return response
        response.success, response.message = result.success, result.message
        response.total_time, response.cut = result.total_time, result.cut
        response.moves = [CheckedMove(line=m.line, command=m.command, verdict=m.verdict,
                                      duration=m.duration, reason=m.reason)
                          for m in result.moves]
        return response

    def _quietly_at_shutdown(self, fn, *args) -> None:
        """Call fn; once the node shuts down (the action server is going), a failure is none."""
        try:
            fn(*args)
        except Exception:
            if self.node.context.ok():
                raise


def compiled(source: str, name: str, points: str) -> Program:
    """A RoboLine program of a goal or request; SourceError when it does not compile."""
    name = name or "<program>"
    if len(source) + len(points) > MAX_PROGRAM:
        raise SourceError(Source("", name), 1, 1, f"the program and its points are "
                          f"{len(source) + len(points)} characters: at most {MAX_PROGRAM}")
    taught = parse_points(Source(points, f"{name} (points)")) if points else None
    return compile_source(Source(source, name), taught)


def _offset(error: StrolicError | None) -> int:
    return -1 if error is None or error.offset is None else error.offset
