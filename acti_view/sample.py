"""What the view shows, read from the world and the cores without holding up the simulation.

PyBullet may only be called from the simulation thread, so `WorldSampler` copies the joint
states and the base pose there (two getters, every few steps); everything else is read from the
cores, which sample the world themselves. Device queues are copied under the device lock (a
list copy) and evaluated outside it.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from acti_motion.arm.core import (STATE_ALARM, STATE_BUFFER_FULL, STATE_MOVING, STATE_PAUSED,
                                  STATE_SERVO_ON, ArmCore)
from acti_motion.executor import Device, MotionExecutor
from acti_motion.vehicle.core import VehicleCore
from acti_sim.world import World

STATE_BITS = ((STATE_SERVO_ON, "servo on"), (STATE_MOVING, "moving"), (STATE_ALARM, "alarm"),
              (STATE_BUFFER_FULL, "queue full"), (STATE_PAUSED, "paused"))


@dataclass(frozen=True)
class WorldSample:
    """Joint positions by name (rad, m) and the base_link pose in the world (m, quaternion xyzw)."""
    joints: dict[str, float]
    base_position: tuple[float, float, float]
    base_orientation: tuple[float, float, float, float]


class WorldSampler:
    """Copies what the view needs from the world on the simulation thread, every `every` steps
    while `active` (the view sets it while a page is open: with none it costs nothing)."""

    def __init__(self, executor: MotionExecutor, every: int) -> None:
        self.latest = self._read(executor.world)
        self.active = False
        self.count = 0                  # samples taken: a new one shows the world is current
        executor.after_step(self._sample, every=every)

    def _sample(self, world: World) -> None:
        if self.active:
            self.latest = self._read(world)
            self.count += 1

    @staticmethod
    def _read(world: World) -> WorldSample:
        names, positions, _ = world.joint_states()
        position, orientation = world.base_link_pose()
        return WorldSample(dict(zip(names, positions)), position, orientation)


@dataclass
class ArmPanel:
    state: int
    queue_length: int
    alarms: list[str]
    motion_id: int
    motion_label: str
    progress: float


@dataclass
class BasePanel:
    state: int
    state_string: str
    position_mm_deg: tuple[float, float, float]
    battery_v: float
    queue_length: int


@dataclass
class ViewSample:
    """One frame of the view: the pose of everything and the panel's values."""
    world: WorldSample
    control_point: np.ndarray                 # world frame, m
    arm_targets: list[np.ndarray] = field(default_factory=list)   # world frame, m
    odometry: tuple[float, float, float] = (0.0, 0.0, 0.0)   # x, y (m), theta (rad): odom frame
    base_targets: list[tuple[float, float]] = field(default_factory=list)   # odom frame, m
    arm: ArmPanel | None = None
    base: BasePanel | None = None


def state_words(state: int) -> str:
    """The arm's state word in words: '0x03 servo on, moving'."""
    names = [name for bit, name in STATE_BITS if state & bit]
    return f"0x{state:02X} " + (", ".join(names) if names else "servo off")


def pose_matrix(position: tuple[float, float, float],
                quaternion_xyzw: tuple[float, float, float, float]) -> np.ndarray:
    x, y, z, w = quaternion_xyzw
    T = np.eye(4)
    T[:3, :3] = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                 [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                 [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    T[:3, 3] = position
    return T


def queued_ends(device: Device) -> list:
    """The set-point where each queued motion (the current one first) ends."""
    with device.lock:
        motions = ([device.current] if device.current is not None else []) + list(device.queue)
    return [m.motion.at(m.motion.duration) for m in motions]


class Reader:
    """Reads a `ViewSample` from the cores (either may be absent) and the world sampler."""

    def __init__(self, sampler: WorldSampler, arm: ArmCore | None,
                 vehicle: VehicleCore | None) -> None:
        self.sampler = sampler
        self.arm = arm
        self.vehicle = vehicle

    def read(self) -> ViewSample:
        world = self.sampler.latest
        base = pose_matrix(world.base_position, world.base_orientation)
        sample = ViewSample(world, base[:3, 3].copy())
        if self.arm is not None:
            self._read_arm(sample, base)
        if self.vehicle is not None:
            self._read_base(sample)
        return sample

    def _read_arm(self, sample: ViewSample, base: np.ndarray) -> None:
        arm = self.arm
        arm_frame = base @ arm.frames.base          # the robot frame in the world

        def world_point(q: np.ndarray) -> np.ndarray:
            return (arm_frame @ arm.tool_pose(q))[:3, 3]
        sample.control_point = world_point(arm.feedback_joints)
        sample.arm_targets = [world_point(end.joints) for end in queued_ends(arm.device)]
        motion_id, label, progress, queued = arm.motion_status()
        sample.arm = ArmPanel(arm.state_word(), queued,
                              [f"0x{a.code:X} {a.description}" for a in arm.alarms],
                              motion_id, label, progress)

    def _read_base(self, sample: ViewSample) -> None:
        v = self.vehicle
        pose = v.odometry.pose                      # the spec's position (set_position's frame)
        odom, frame = v.odometry.continuous()       # odom: the world's frame where the base started
        sample.odometry = (odom.x, odom.y, odom.theta)
        to_odom = frame.inverse()
        sample.base_targets = [(p.x, p.y) for p in (to_odom.compose(end)
                                                   for end in queued_ends(v.device))]
        state = v.state()
        sample.base = BasePanel(int(state), v.state_string(state),
                                (1000.0 * pose.x, 1000.0 * pose.y, math.degrees(pose.theta)),
                                v.battery.voltage, v.device.queue_length)
