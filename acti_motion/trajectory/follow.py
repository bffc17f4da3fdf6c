"""Trajectories on the arm's motion queue: a trajectory is one motion of the arm's queue, so the
ACT stop, pause, resume, servo_off, the soft-limit watch and the alarms govern it as any move.

A trajectory starts from where the arm is. It is refused while ACT motions are queued or running
or a STROLIC program runs (its first point would not be where the arm is when it starts); one that
comes while a trajectory runs replaces it (preemption), taking over a few control periods ahead of
the arm from the set-point there, without a stop."""
from __future__ import annotations

from typing import Callable, Sequence

import numpy as np

from acti_motion.arm.core import ArmCore
from acti_motion.arm.trajectories import ArmSetpoint
from acti_motion.executor import STALE, Device
from acti_motion.replies import Refused, Reply, ReturnCode
from acti_motion.trajectory.interpolation import PiecewisePolynomial, State
from acti_motion.trajectory.limits import FollowPlan, JointLimits, check_limits, follow_plan
from acti_motion.trajectory.motion import TrajectoryMotion
from acti_motion.trajectory.validation import InvalidTrajectory, ValidTrajectory
from acti_sim.world import ARM_JOINTS

LOOKAHEAD_STEPS = 3          # a replacement takes over this many control periods ahead (first try)
CARTESIAN_CHECK_S = 0.01     # the control point is checked against the Cartesian box this densely
PREEMPTED = "preempted by a newer trajectory"
PlanOf = Callable[[State, float], FollowPlan]


class _Invalid(Refused):
    """An InvalidTrajectory carried through the arm's planning (which passes only refusals)."""

    def __init__(self, invalid: InvalidTrajectory) -> None:
        super().__init__(ReturnCode.VALUE_ERR, str(invalid))
        self.invalid = invalid


class ArmTrajectories:
    """Follows trajectories on `core`'s queue; `program_running()` says whether a STROLIC program
    runs (its moves come one by one, so the queue alone does not show it)."""

    def __init__(self, core: ArmCore, program_running: Callable[[], bool] = lambda: False,
                 joints: Sequence[str] = ARM_JOINTS) -> None:
        self.core, self.joints = core, tuple(joints)
        self.program_running = program_running

    @property
    def device(self) -> Device:
        return self.core.device

    def limits(self) -> JointLimits:
        """The joint limits in force: the soft limits, the max speeds, and the accelerations they
        allow in the shortest accel time (as for the CP moves)."""
        c = self.core
        speed = np.radians(c.max_speed_joint)
        return JointLimits(self.joints, np.radians(c.soft_limit_joint[:, 0]),
                           np.radians(c.soft_limit_joint[:, 1]), speed,
                           speed / c.min_accel_time_joint)

    def now(self) -> float:
        """The controller's time: the simulated time (the /clock timeline)."""
        return self.core.executor.world.time

    def running(self) -> TrajectoryMotion | None:
        """The trajectory that runs and may be replaced (none while a stop decelerates it)."""
        cur = self.device.current
        if cur is None or self.device.stopping or self.device.queue \
                or not isinstance(cur.motion, TrajectoryMotion):
            return None
        return cur.motion

    def follow(self, valid: ValidTrajectory, label: str) -> tuple[int, TrajectoryMotion]:
        """Queue the trajectory, or let it replace the one that runs; its motion id and motion.
        Refused (servo off, an alarm, the arm busy with ACT motions or a program) or
        InvalidTrajectory (it breaks a limit, or does not start where the arm is) say why."""
        return self.follow_plan(
            lambda start, now: follow_plan(valid, start, now, self.joints), label)

    def follow_plan(self, plan_of: PlanOf, label: str) -> tuple[int, TrajectoryMotion]:
        """`follow` for the knots plan_of(the arm's state where they begin, the time then)."""
        self.core._check_can_move()
        if self.program_running():
            raise self._busy("a STROLIC program runs")
        for _ in range(3):
            if self.running() is not None:
                out = self.device.edit_planned(*self._replacement(plan_of, label))
                if out is not STALE:
                    return out
                continue
            if self.device.current is None and self.device.queue \
                    and self.device.edit(self._preempt_unstarted):
                continue                            # now planned from rest where it would start
            planned: list[TrajectoryMotion] = []
            try:
                reply = self.core._submit(self._from_rest(plan_of, planned), label)
            except _Invalid as e:
                raise e.invalid from None
            if isinstance(reply, Reply):            # accepted while a stop decelerates: doomed
                raise Refused(ReturnCode.STATUS_ERR, reply.comment)
            return reply["motion_id"], planned[-1]
        raise Refused(ReturnCode.STATUS_ERR, "the arm changed faster than the trajectory could be "
                                             "planned: send it again")

    def plan(self, plan_of: PlanOf, start: State, now: float) -> PiecewisePolynomial:
        """The interpolation from `start`, checked against every limit (InvalidTrajectory)."""
        poly = check_limits(plan_of(start, now), self.limits())
        self._check_cartesian(poly)
        return poly

    def _check_cartesian(self, poly: PiecewisePolynomial) -> None:
        core = self.core
        ts = np.linspace(0.0, poly.duration, max(2, int(poly.duration / CARTESIAN_CHECK_S) + 1))
        qs = poly.sample_many(ts)[0]
        positions = core.frames.tool_of(core.kin.flange_many(qs))[:, :3, 3] * 1000.0
        core._check_cartesian_positions(positions, "the trajectory")

    def _from_rest(self, plan_of: PlanOf, planned: list[TrajectoryMotion]) -> Callable[[ArmSetpoint], TrajectoryMotion]:
        def plan(start: ArmSetpoint) -> TrajectoryMotion:
            self._check_idle()
            rest = np.zeros_like(start.joints)
            try:
                poly = self.plan(plan_of, State(start.joints, rest, rest), self.now())
            except InvalidTrajectory as e:
                raise _Invalid(e) from None
            planned.append(TrajectoryMotion(poly, start.finger, self.core.accel_time_joint))
            return planned[-1]
        return plan

    @staticmethod
    def _preempt_unstarted(device: Device) -> bool:
        """Under the device's lock: a trajectory accepted and not started yet, alone on the arm
        (the simulation picks it up within a step or two), is preempted as a running one is:
        a goal sent right after another replaces it instead of finding the arm busy."""
        if device.current is None and len(device.queue) == 1 and not device.stopping \
                and isinstance(device.queue[0].motion, TrajectoryMotion):
            device.discard_queue(PREEMPTED)
            return True
        return False

    def _check_idle(self) -> None:
        d = self.device
        if d.busy:
            raise self._busy(f"{d.queue_length + d.moving} motion(s) (ACT moves, gripper "
                             "commands) running or queued")

    @staticmethod
    def _busy(what: str) -> Refused:
        return Refused(ReturnCode.STATUS_ERR, f"the arm is busy: {what}; a trajectory starts only "
                                              "from an idle arm (wait, or stop first)")

    def _replacement(self, plan_of: PlanOf, label: str) -> tuple[Callable, Callable]:
        """look and plan of `Device.edit_planned` for a trajectory replacing the running one."""
        core, dt = self.core, self.core.executor.dt

        def look(device: Device, attempt: int) -> tuple:
            ahead = LOOKAHEAD_STEPS * dt * 2 ** attempt
            cur = device.current
            t = device.t + ahead
            return cur, t, cur.motion.state(t), self.now() + ahead

        def plan(seen: tuple) -> Callable[[Device], object]:
            cur, t, start, now = seen
            poly = self.plan(plan_of, start, now)
            limits = core.limits.rows

            def commit(device: Device) -> object:
                if device.current is not cur or self.running() is not cur.motion \
                        or device.t > t:
                    return STALE
                motion = cur.motion.handover(t, poly, device.t)
                motion.limits_checked = limits
                new_id = device.renumber(cur, PREEMPTED)
                cur.motion, cur.label = motion, label
                return new_id, motion
            return commit
        return look, plan
