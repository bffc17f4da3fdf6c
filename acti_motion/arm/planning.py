"""Planning and checking a move of the arm: what runs on the caller's thread before it is queued.

A move operation checks its target at once (soft limits, reach: a full queue would hide it), then
hands the device a plan, which the device calls on this same thread from the end of the last
queued move; the motion is queued only if its path passes every check (soft limits, reach), with
the settings read while planning. Planning takes milliseconds, so it runs on the thread of the
service that asks (or of a STROLIC program), never on the simulation thread and never under the
lock that the simulation, `stop` and `pause` take: none of them waits for it. `all_or_nothing`
collects the moves of one thread (thread-local) and queues them together.
A part of `ArmCore` (mixed in; uses its attributes).
"""
from __future__ import annotations

import math
import operator
import threading
from contextlib import contextmanager
from functools import partial
from typing import Callable, Iterator

import numpy as np

from acti_motion.arm.kinematics import FEW_POSTURES, ArmKinematics, Unreachable, rotate_about
from acti_motion.arm.limits import NEAR_LIMIT_DEG, SoftLimits
from acti_motion.arm.poses import Frames
from acti_motion.arm.trajectories import (ArmMotion, ArmSetpoint, CartesianLimits,
                                          CartesianPath, CartesianPlanner, LinearJointPath,
                                          LinePath, SplineJointPath, convex_checkpoints,
                                          positions_along, spline_within)
from acti_motion.profiles import Trapezoid
from acti_motion.replies import Refused, Reply, ReturnCode, floats, value_error

R = ReturnCode

REL_ELBOW_CLEARANCE = math.sin(math.radians(10.0))
REACH_SAMPLES = 64                       # points of a CP path checked against the reach first
MAX_CHECK_SAMPLES = 20000                # points of a CP path checked against the soft limits
NEAR_LIMIT_MM = 1.0      # samples this close to a Cartesian soft limit: checked between, finer


def _near_limits_refined(ss: np.ndarray, values: np.ndarray, evaluate: Callable[[np.ndarray], np.ndarray],
                         lower: np.ndarray, upper: np.ndarray, margin: float,
                         count: int = 16) -> np.ndarray:
    """`values` (rows at the path parameters ss) with `count` more rows, in order, inside every
    interval that has an end within `margin` of a limit: what the path does between two samples
    near a limit is checked too, as the run's watch, which samples every control period, would
    see it (accepted moves tripped it by 1e-6° or 0.12 mm)."""
    near = np.any((values <= lower + margin) | (values >= upper - margin), axis=1)
    todo = np.flatnonzero(near[:-1] | near[1:])
    if not len(todo):
        return values
    t = np.linspace(0.0, 1.0, count + 2)[1:-1]
    extra = (ss[todo, None] + (ss[todo + 1] - ss[todo])[:, None] * t).ravel()
    order = np.argsort(np.concatenate([ss, extra]), kind="stable")
    return np.vstack([values, evaluate(extra)])[order]


def _well_inside(values: np.ndarray | list[list[float]], bounds: np.ndarray | list[list[float]],
                 margin: float) -> bool:
    """Every row of a few samples (at most FEW_POSTURES) lies more than `margin` inside the
    bounds (rows: lower, upper): then no sample is near a limit (nothing to refine) and none
    is outside. In plain floats: on a cold core a short PTP move's numpy checks of its two
    samples cost ~25 µs of its accept; a longer path goes to numpy (False)."""
    if len(values) > FEW_POSTURES:
        return False
    lower, upper = zip(*(bounds.tolist() if isinstance(bounds, np.ndarray) else bounds))
    lower, upper = [lo + margin for lo in lower], [hi - margin for hi in upper]
    rows = values.tolist() if isinstance(values, np.ndarray) else values
    return all(all(map(operator.lt, lower, row)) and all(map(operator.lt, row, upper))
               for row in rows)


def _position_mm(pose: np.ndarray) -> list[float]:
    """The position of a pose (4×4, m) in mm, in plain floats (one numpy call)."""
    rows = pose.tolist()
    return [rows[0][3] * 1000.0, rows[1][3] * 1000.0, rows[2][3] * 1000.0]


def _line_positions_mm(kin: ArmKinematics, frames: Frames, q0: list[float], delta: list[float],
                       ss: np.ndarray | list[float],
                       position_at: Callable[[list[float]], list[float]] | None = None
                       ) -> np.ndarray | list[list[float]]:
    """The control point (mm, robot frame) at each s of the joint line q0 + s·delta (rad): a
    few posture by posture in plain floats (a list of rows; `position_at`, if given, computes
    one), more at once in numpy (an array)."""
    if len(ss) <= FEW_POSTURES:
        if position_at is None:
            def position_at(q: list[float]) -> list[float]:
                return _position_mm(frames.tool_of(kin.flange(np.array(q))))
        return [position_at([a + s * d for a, d in zip(q0, delta)]) for s in ss]
    qs = np.array(q0) + np.asarray(ss)[:, None] * np.array(delta)
    return frames.tool_of(kin.flange_many(qs))[:, :3, 3] * 1000.0


def _first_exit(values: np.ndarray, lower: np.ndarray, upper: np.ndarray,
                tol: float) -> tuple[int, int] | None:
    """(sample, axis) where rows of `values` first go from inside [lower, upper] to outside,
    or where the last row is outside; None when the path stays (or ends) inside."""
    inside = (values >= lower - tol) & (values <= upper + tol)
    if inside.all():                     # the usual case, at the least cost
        return None
    exits = np.argwhere(inside[:-1] & ~inside[1:])
    if len(exits):
        k, axis = exits[0]
        return int(k) + 1, int(axis)
    outside = np.flatnonzero(~inside[-1])
    if len(outside):
        return len(values) - 1, int(outside[0])
    return None


class MovePlanning:
    """The caller's-thread part of ArmCore: checks and plans of the moves, and their queueing
    (mixed in: it reads ArmCore's kinematics, frames, soft limits, motion settings and device)."""

    planner: CartesianPlanner
    _batch: threading.local               # the moves an `all_or_nothing` collects
    _batching: set[int]                   # the threads with an `all_or_nothing` block open
    _check_can_move: Callable[..., None]
    servo: bool
    _alarms: list
    limits: SoftLimits                    # the soft limits in force (made anew when one is set)
    # (frames, joints, position (mm), the reach's radius in these frames (mm))
    _posture_memo: tuple[Frames, list[float], list[float], float] | None
    # (limits, a kept position, its least distance (mm) from the Cartesian soft limits)
    _depth_memo: tuple[SoftLimits, list[float], float] | None
    _joints_memo: tuple[np.ndarray, list[float]] | None   # (a PTP plan's end joints, floats)
    _speeds_memo: tuple[np.ndarray, float, list[float]] | None      # (rated, ratio, speeds)
    _reach_memo: tuple[Frames, list[float], float] | None          # (frames, shoulder, radius)
    _limits_memo: tuple[np.ndarray, tuple, CartesianLimits] | None  # (rated, settings, limits)

    # === checks ======================================================================================
    def _check_target(self, target: np.ndarray, label: str, frames: Frames | None = None,
                      psi: float | None = None) -> None:
        """A target (4×4, m) within the Cartesian soft limit and the arm's reach and, given its
        elbow `psi` (rad), one a joint solution within the joint soft limits reaches, else
        VALUE_ERR. None of this depends on the start (IK tries all eight branches): absolute
        targets are checked before the queue is looked at (a full queue would have hidden it),
        and again when planned, with the frames in force then."""
        frames = self.frames if frames is None else frames
        self._check_cartesian_positions(target[None, :3, 3] * 1000.0, label)
        self._check_reach(target[None, :3, 3], frames, label)
        if psi is not None:
            lim = np.radians(self.soft_limit_joint)
            try:
                self.kin.solve(frames.flange_of(target), self.device.queued_end.joints, psi=psi,
                               lower=lim[:, 0], upper=lim[:, 1])
            except Unreachable as e:
                raise value_error(f"{label}: {e}") from None

    def _check_reach(self, positions: np.ndarray, frames: Frames, label: str) -> None:
        """Control-point positions (robot frame, m) no farther from the shoulder than the arm,
        hand and control-point offset reach, else VALUE_ERR: checked before any IK or planning,
        so a target kilometres away is refused at once."""
        memo = self._reach_memo                       # made again when the frames change
        if memo is None or memo[0] is not frames:
            to_robot = frames.base_inverse
            memo = self._reach_memo = (frames, (to_robot[:3, :3] @ self.kin.shoulder
                                                + to_robot[:3, 3]).tolist(),
                                       self.planner.reach_radius(frames))
        _, centre, radius = memo
        if len(positions) <= FEW_POSTURES:            # a target, a line's ends: plain floats
            if all(math.dist(p, centre) <= radius for p in positions.tolist()):
                return
        shoulder = np.array(centre)
        dist = np.linalg.norm(positions - shoulder, axis=1)
        far = np.flatnonzero(~(dist <= radius + 1e-9))
        if len(far):
            k = int(far[0])
            where = ("the target" if k == len(positions) - 1 else
                     f"the path at {100.0 * k / max(1, len(positions) - 1):.0f} %")
            raise value_error(f"{label}: {where} is out of reach: {dist[k] * 1e3:.6g} mm from the "
                              f"shoulder, the arm reaches {radius * 1e3:.1f} mm")

    def _check_step(self, delta: np.ndarray, label: str) -> None:
        """A relative step (4×4, m) longer than the reach's ball is wide ends out of reach from
        any start: VALUE_ERR before the queue is looked at (a full queue would have hidden it)."""
        diameter = 2.0 * self.planner.reach_radius(self.frames)
        step = math.hypot(*delta[:3, 3].tolist())
        if step > diameter + 1e-9:
            raise value_error(f"{label}: a step of {step * 1e3:.6g} mm is out of reach from any "
                              f"start: the arm reaches {diameter * 1e3:.1f} mm across")

    def _check_cartesian_positions(self, positions_mm: np.ndarray, label: str) -> None:
        lim = self.soft_limit_cartesian
        if _well_inside(positions_mm, lim, 0.0):      # a target, a line's ends: at once
            return
        hit = _first_exit(positions_mm, lim[:, 0], lim[:, 1], 1e-9)
        if hit is not None:
            k, axis = hit
            where = "the target" if k == len(positions_mm) - 1 else "the path"
            raise value_error(f"{label}: {where} leaves the Cartesian soft limit: "
                              f"{'xyz'[axis]} = {positions_mm[k, axis]:.10g} mm, limit "
                              f"[{lim[axis, 0]:g}, {lim[axis, 1]:g}] mm")

    def _check_joint_path(self, qs_deg: np.ndarray, label: str) -> None:
        lim = self.soft_limit_joint
        hit = _first_exit(qs_deg, lim[:, 0], lim[:, 1], 1e-9)
        if hit is not None:
            k, j = hit
            raise value_error(f"{label}: the path leaves the joint soft limit: J{j + 1} = "
                              f"{qs_deg[k, j]:.10g}°, limit [{lim[j, 0]:g}, {lim[j, 1]:g}]°")

    def _check_joint_spline(self, spline: SplineJointPath, label: str) -> None:
        """A CP path's joint spline within the joint soft limits: at once where a bound over
        each piece keeps it clear of them (as the samples would find), else at 4 samples per
        IK sample, finer near a limit."""
        lim = self.soft_limit_joint
        if spline_within(spline, *self.limits.clear):
            return
        dense = np.linspace(0.0, 1.0, 4 * len(spline.ss))

        def joints_deg(ss: np.ndarray) -> np.ndarray:
            return np.degrees(spline.spline(ss))
        self._check_joint_path(_near_limits_refined(
            dense, joints_deg(dense), joints_deg, lim[:, 0], lim[:, 1], NEAR_LIMIT_DEG), label)

    # === queueing ======================================================================================
    def queue_joint_move(self, goal_of: Callable[[ArmSetpoint], np.ndarray | list[float]] | None,
                         label: str, speed_ratio: float | None = None,
                         ramp: float | None = None, *, step: list[float] | None = None) -> dict:
        """A PTP move to goal_of(start) (rad), or by `step` (rad) from the start (goal_of None):
        synchronized trapezoid at the joint speed ratio and accel time (or the given ones:
        STROLIC programs keep their own)."""
        speed = self._joint_speeds(self.speed_joint if speed_ratio is None else speed_ratio)
        ramp = self.accel_time_joint if ramp is None else ramp
        return self._submit(partial(self._plan_joint_move, goal_of, step, label, speed, ramp),
                            label)

    def _plan_joint_move(self, goal_of: Callable[[ArmSetpoint], np.ndarray | list[float]] | None,
                         step: list[float] | None, label: str, speed: list[float], ramp: float,
                         start: ArmSetpoint) -> ArmMotion:
        """`queue_joint_move`'s plan from `start`. The 7 joints' arithmetic is in plain floats,
        with the few Python calls it can (numpy's calls cost 1 … 3 µs each on the cold core of
        an accept, a Python call ~0.5 µs)."""
        frames = self.frames          # read while planning: the offsets wait for it
        memo = self._joints_memo      # the start's floats: a move starts where the last ended
        q0 = memo[1] if memo is not None and memo[0] is start.joints else start.joints.tolist()
        goal = list(map(operator.add, q0, step)) if goal_of is None else floats(goal_of(start))
        self.limits.check_target(list(map(math.degrees, goal)), label)
        delta = list(map(operator.sub, goal, q0))
        end = list(map(operator.add, q0, delta))
        path = LinearJointPath.from_floats(start.joints, delta, end)
        self._joints_memo = (path.end, end)     # where the next move starts
        if not self._line_near_kept_posture_inside(frames, q0, end):
            self._check_joint_line(frames, q0, delta, label)
        timing = Trapezoid.for_axes(delta, speed, ramp)
        return ArmMotion(path, timing, start.finger, start.finger, ramp, "joint")

    def _check_joint_line(self, frames: Frames, q0: list[float], delta: list[float],
                          label: str) -> None:
        """The control point along the joint line q0 + s·delta (rad) within the Cartesian soft
        limit, at every degree of the longest joint's way and finer near a limit, else
        VALUE_ERR."""
        steps = 1 + max(1, math.ceil(math.degrees(max(map(abs, delta)))))

        def position_at(q: list[float]) -> list[float]:
            return self._position_at(frames, q)

        def positions_mm(ss: np.ndarray | list[float]) -> np.ndarray:
            return np.asarray(_line_positions_mm(self.kin, frames, q0, delta, ss, position_at))
        ss = [k / (steps - 1) for k in range(steps)]
        positions = _line_positions_mm(self.kin, frames, q0, delta, ss, position_at)
        limits = self.limits
        if not _well_inside(positions, limits.cartesian_floats, NEAR_LIMIT_MM):
            lim = limits.cartesian
            self._check_cartesian_positions(_near_limits_refined(
                np.array(ss), np.asarray(positions), positions_mm, lim[:, 0], lim[:, 1],
                NEAR_LIMIT_MM), label)

    def _joint_speeds(self, ratio: float) -> list[float]:
        """The joints' speeds (rad/s) at `ratio` %, made again only when the ratio or the rated
        speeds changed (each setter assigns a new array; a numpy call on every accept)."""
        memo = self._speeds_memo
        if memo is None or memo[0] is not self.max_speed_joint or memo[1] != ratio:
            rated = self.max_speed_joint
            memo = self._speeds_memo = (rated, ratio, [math.radians(v) * ratio / 100.0
                                                       for v in rated.tolist()])
        return memo[2]

    def _line_near_kept_posture_inside(self, frames: Frames, q0: list[float],
                                       end: list[float]) -> bool:
        """The joint line q0 → end (rad) keeps the control point more than NEAR_LIMIT_MM inside
        the Cartesian soft limit, told without a posture's forward kinematics near the last
        posture computed (`_position_at`): a joint turns the control point about an axis no
        farther from it than the reach's radius, so a posture q lies within that radius times
        ‖q − q_kept‖₁ of the kept position, and every posture of the line within the larger of
        its ends' (the norm is convex). Where that ball is well inside, so is every sample the
        line's check takes (the same answer); False sends the line to that check. The kept
        position's depth inside the box is kept too, per limits in force (`_depth_memo`); the
        1e-6 mm the ball is widened by covers its rounding."""
        memo = self._posture_memo
        if memo is None or memo[0] is not frames:
            return False
        _, kept, position, reach_mm = memo
        limits, depth = self.limits, self._depth_memo
        if depth is None or depth[0] is not limits or depth[1] is not position:
            depth = self._depth_memo = (limits, position, min(
                min(map(operator.sub, position, limits.box_lower)),
                min(map(operator.sub, limits.box_upper, position))))
        far = max(sum(map(abs, map(operator.sub, q0, kept))),
                  sum(map(abs, map(operator.sub, end, kept))))
        return far * reach_mm + NEAR_LIMIT_MM + 1e-6 < depth[2]

    def _position_at(self, frames: Frames, q: list[float]) -> list[float]:
        """The control point (mm) of posture q (rad) in `frames`; the last one computed is kept:
        a PTP move ends where the next one queued starts (the very floats of `path.q(1.0)`),
        so an accept of a short move computes one posture instead of two."""
        memo = self._posture_memo
        if memo is not None and memo[0] is frames and memo[1] == q:
            return memo[2]
        position = _position_mm(frames.tool_of(self.kin.flange(np.array(q))))
        self._posture_memo = (frames, q, position, self.planner.reach_radius(frames) * 1000.0)
        return position

    def _elbow_goal(self, start_q: np.ndarray, flange: np.ndarray, psi: float | None,
                    turn: float) -> tuple[float | None, float]:
        """(psi, turn) for the planners. Abs: psi as given. Rel: psi = the start's arm angle +
        turn, except where the start or the target is near the arm angle's undefined direction
        (wrist left or right of the shoulder): there the elbow is carried along without twist
        and turned by `turn` (psi None)."""
        if psi is not None:
            return psi, 0.0
        kin = self.kin
        u0, n0 = kin.elbow_direction(start_q)
        u1 = kin.wrist_direction(flange)
        if min(kin.reference_strength(u0), kin.reference_strength(u1)) > REL_ELBOW_CLEARANCE:
            return kin.angle_of(u0, n0) + turn, 0.0
        return None, turn

    def _queue_ptp_cartesian(self, target_of: Callable[[np.ndarray], np.ndarray], label: str, *,
                             psi: float | None = None, turn: float = 0.0) -> dict:
        """A PTP move to the control-point pose target_of(start pose), with the elbow at arm
        angle `psi`, or (Rel) turned by `turn` (rad) from where it starts."""
        kin = self.kin
        lo, hi = np.radians(self.soft_limit_joint[:, 0]), np.radians(self.soft_limit_joint[:, 1])

        def goal_of(start: ArmSetpoint) -> np.ndarray:
            frames = self.frames          # read while planning: the offsets wait for it
            target = target_of(frames.tool_of(kin.flange(start.joints)))
            self._check_target(target, label, frames)
            flange = frames.flange_of(target)
            goal_psi, goal_turn = self._elbow_goal(start.joints, flange, psi, turn)
            try:
                if goal_psi is not None:
                    return kin.solve(flange, start.joints, psi=goal_psi, lower=lo, upper=hi)
                u0, n0 = kin.elbow_direction(start.joints)
                w = kin.wrist_of(flange) - kin.shoulder
                u1 = w / max(float(np.linalg.norm(w)), 1e-12)
                elbow = rotate_about(u1, goal_turn) @ kin.transport(n0, u0, u1)
                return kin.solve(flange, start.joints, elbow_dir=elbow, lower=lo, upper=hi)
            except Unreachable as e:
                raise value_error(f"{label}: {e}") from None
        return self.queue_joint_move(goal_of, label)

    def _cartesian_limits(self, speed_ratio: float, ramp: float) -> CartesianLimits:
        """The CP profile's limits at a speed ratio (%) and accel time (s), made again only when
        these or a rated speed or the joints' accel time changed (each setter assigns anew)."""
        key = (speed_ratio, ramp, self.max_speed_cartesian, self.min_accel_time_joint)
        memo = self._limits_memo
        if memo is None or memo[0] is not self.max_speed_joint or memo[1] != key:
            (v, w), ratio = self.max_speed_cartesian, speed_ratio / 100.0
            joint_velocity = np.radians(self.max_speed_joint)
            memo = self._limits_memo = (self.max_speed_joint, key, CartesianLimits(
                speed=v * ratio / 1000.0, angular_speed=math.radians(w * ratio), ramp=ramp,
                joint_velocity=joint_velocity,
                joint_accel=joint_velocity / self.min_accel_time_joint))
        return memo[2]

    def queue_cartesian(self, path_of: Callable[[np.ndarray], CartesianPath], label: str, *,
                         psi: float | None = None, turn: float = 0.0,
                         speed_ratio: float | None = None, ramp: float | None = None) -> dict:
        """A CP move along path_of(start pose); the elbow ends at arm angle `psi`, or (Rel) is
        turned by `turn` (rad) from where it starts. Speed ratio and accel time: the port's
        settings unless given."""
        limits = self._cartesian_limits(
            self.speed_cartesian if speed_ratio is None else speed_ratio,
            self.accel_time_cartesian if ramp is None else ramp)

        def plan(start: ArmSetpoint) -> ArmMotion:
            frames = self.frames          # read while planning: the offsets wait for it
            try:
                path = path_of(frames.tool_of(self.kin.flange(start.joints)))
                self.planner.check_length(path, frames)
            except ValueError as e:
                raise value_error(f"{label}: {e}") from None
            coarse = convex_checkpoints(path, REACH_SAMPLES)
            self._check_cartesian_positions(coarse * 1000.0, label)
            self._check_reach(coarse, frames, label)
            if not isinstance(path, LinePath):       # a line's ends told it all (convex)
                ss = np.linspace(0.0, 1.0, min(MAX_CHECK_SAMPLES,
                                               1 + max(2, math.ceil(path.length / 0.002))))
                self._check_cartesian_positions(positions_along(path, ss) * 1000.0, label)
            goal_psi, goal_turn = self._elbow_goal(start.joints, frames.flange_of(path.pose(1.0)),
                                                   psi, turn)
            try:
                result = self.planner.plan(path, frames, start.joints, limits, psi=goal_psi,
                                           turn=goal_turn)
            except Unreachable as e:
                raise value_error(f"{label}: {e}") from None
            self._check_joint_spline(result.path, label)
            return ArmMotion(result.path, result.timing, start.finger, start.finger, limits.ramp,
                             "cartesian")
        return self._submit(plan, label)

    def queue_gripper(self, ratio: int, label: str) -> dict:
        return self.queue_gripper_to(self.finger_max * ratio / 100.0, label)

    def queue_gripper_to(self, finger: float, label: str) -> dict:
        """A gripper move of each finger to `finger` m from the centre (0 … finger_max)."""
        self._check_can_move()
        speed = self.config.gripper_speed / 2000.0      # one finger, m/s
        ramp = self.min_accel_time_joint

        def plan(start: ArmSetpoint) -> ArmMotion:
            timing = Trapezoid.for_axes([finger - start.finger], [speed], ramp)
            return ArmMotion(LinearJointPath(start.joints, start.joints), timing, start.finger,
                             finger, ramp, "gripper")
        return self._submit(plan, label)

    def _submit(self, plan: Callable[[ArmSetpoint], ArmMotion], label: str) -> dict | Reply:
        """Queue one planned move; inside `all_or_nothing` (on this thread), collect it."""
        guarded = partial(self._guarded_plan, plan, label)
        # (a thread-local read, ~1 µs on the cold core of an accept, only while a block is open)
        collected = getattr(self._batch, "plans", None) if self._batching else None
        if collected is not None:
            collected.append((guarded, label))
            return {"motion_id": 0}
        got = self.device.submit_doomed([(guarded, label)])
        if got is None:
            raise self._full()
        (motion_id,), why = got
        if why is not None:         # OK as 5.4.19 has it, and said: its wait will say the same
            return Reply(R.OK, f"discarded: {why} (a stop discards every command given until "
                               "the arm is at rest)", {"motion_id": motion_id})
        return {"motion_id": motion_id}

    @contextmanager
    def all_or_nothing(self) -> Iterator[list[int]]:
        """The moves queued inside the block (on this thread) go in together when it ends, each
        planned from the end of the one before, or none of them: a refusal of any, or a queue
        without room for all (FULL_MOTION_QUEUE_ERR), queues nothing. The list yielded gets
        their ids, in order (a program's pose sequence is one command)."""
        plans: list = []
        self._batch.plans = plans
        me = threading.get_ident()
        self._batching.add(me)
        ids: list[int] = []
        try:
            yield ids
        finally:
            self._batch.plans = None
            self._batching.discard(me)
        if plans:
            got = self.device.submit_all(plans)
            if got is None:
                raise self._full()
            ids.extend(got)

    def _full(self) -> Refused:
        return Refused(R.FULL_MOTION_QUEUE_ERR,
                       f"the motion queue is full ({self.device.capacity} motions): wait or stop")

    def _guarded_plan(self, plan: Callable[[ArmSetpoint], ArmMotion], label: str,
                      start: ArmSetpoint) -> ArmMotion:
        """plan(start), as the device calls it: a refusal passes; any other failure of planning
        is this request's NG, said. The servo and alarms are checked again here, after the
        device took its generation: a servo_off (or an alarm) that came while this request
        waited for another's plan stopped an idle arm, and the move would have been queued
        behind it."""
        if not self.servo or self._alarms:     # (the attributes `_check_can_move` reads)
            self._check_can_move()
        limits = self.limits.rows
        try:
            motion = plan(start)
        except Refused:
            raise
        except Unreachable as e:
            raise value_error(f"{label}: {e}") from None
        except Exception as e:
            raise Refused(R.NG, f"{label} could not be planned: {type(e).__name__}: {e}") \
                from None
        if not math.isfinite(motion.duration):
            raise value_error(f"{label}: the move would take forever at these settings")
        motion.limits_checked = limits
        return motion
