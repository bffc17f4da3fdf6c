"""Messages of the controller interfaces (trajectory_msgs, control_msgs) as trajectory-core values
and back: the one place where they are converted."""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np
from builtin_interfaces.msg import Duration
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from acti_motion.trajectory.interpolation import State
from acti_motion.trajectory.tolerances import RequestedTolerance
from acti_motion.trajectory.validation import RequestedPoint, RequestedTrajectory


def seconds(t: Any) -> float:
    """A builtin_interfaces Time or Duration in seconds."""
    return t.sec + t.nanosec * 1e-9


def duration(s: float) -> Duration:
    sec = int(s // 1)
    return Duration(sec=sec, nanosec=int(round((s - sec) * 1e9)) % 1_000_000_000)


def requested_trajectory(msg: JointTrajectory) -> RequestedTrajectory:
    return RequestedTrajectory(
        list(msg.joint_names),
        [RequestedPoint(seconds(p.time_from_start), list(p.positions), list(p.velocities),
                        list(p.accelerations), list(p.effort)) for p in msg.points],
        seconds(msg.header.stamp))


def requested_tolerances(msgs: Sequence[Any]) -> list[RequestedTolerance]:
    """control_msgs/JointTolerance[] as the core's."""
    return [RequestedTolerance(m.name, m.position, m.velocity, m.acceleration) for m in msgs]


def trajectory_point(state: State | None = None, positions: np.ndarray | None = None,
                     velocities: np.ndarray | None = None) -> JointTrajectoryPoint:
    """A point of feedback: a reference state, or measured positions and velocities."""
    if state is not None:
        positions, velocities = state.positions, state.velocities
    point = JointTrajectoryPoint(positions=[float(x) for x in positions])
    if velocities is not None:
        point.velocities = [float(x) for x in velocities]
    if state is not None:
        point.accelerations = [float(x) for x in state.accelerations]
    return point
