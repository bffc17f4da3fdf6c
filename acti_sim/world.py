"""The PyBullet world of the mobile manipulator: one headless physics client, stepped by its owner.

The world knows nothing of queues, services or ROS: it takes joint and wheel set-points and reports
what the physics did (joint positions, wheel rotation, ground-truth base pose, bumper contacts).
"""
from __future__ import annotations

import functools
import math
import os
import threading
from dataclasses import dataclass

import numpy as np

from acti_sim.quiet import output_silenced
from acti_sim.unlocked_step import unlocked_step

with output_silenced():         # its build time, printed on import
    import pybullet
import pybullet_data

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))      # the project's directory
URDF_PATH = os.path.join(ROOT, "urdf", "mobile_manipulator.urdf")
ARM_JOINTS = tuple(f"joint{i}" for i in range(1, 8))
GRIPPER_JOINTS = ("gripper_finger_left_joint", "gripper_finger_right_joint")
WHEEL_JOINTS = ("left_wheel_joint", "right_wheel_joint")
BUMPER_LINK = "bumper"
CASTER_LINKS = ("front_caster", "rear_caster")
# the links that make the base's footprint on the floor (the arm is above it)
BASE_LINKS = ("base_link", BUMPER_LINK, *CASTER_LINKS, "left_wheel", "right_wheel")

HELD = "held"                          # the wheels' motor target while `hold_wheels`
# The robot's links collide in this group (PyBullet: static bodies are group 2, dynamic ones 1):
# rays cast by the robot's own sensors leave it out, and see everything else (`cast_rays`).
ROBOT_GROUP = 4
EVERYTHING_BUT_ROBOTS = -1 ^ ROBOT_GROUP
OBSTACLE_RGBA = (0.62, 0.55, 0.45, 1.0)

class PhysicsClient:
    """PyBullet's functions bound to one physics client. pybullet_utils' BulletClient binds them
    anew on every attribute access (an `inspect` call and a partial each time, several times a
    step); here each is bound once, on first use. The step runs without the GIL
    (`acti_sim.unlocked_step`): every call holds the client's lock instead, so none runs
    while the physics steps, whichever thread makes it."""

    def __init__(self) -> None:
        self._id = pybullet.connect(pybullet.DIRECT)
        self.lock = threading.Lock()
        self._step = unlocked_step(pybullet.__file__, self._id)

    def __getattr__(self, name: str):
        fn, lock = functools.partial(getattr(pybullet, name), physicsClientId=self._id), self.lock

        def locked(*args, **kwargs):
            with lock:
                return fn(*args, **kwargs)
        setattr(self, name, locked)
        return locked

    def stepSimulation(self) -> None:  # noqa: N802 (pybullet's name)
        with self.lock:
            if self._step is None:      # the handle is freed: pybullet's own answer, no crash
                raise pybullet.error("Not connected to physics server.")
            self._step()

    def disconnect(self) -> None:
        with self.lock:
            self._step = None
            pybullet.disconnect(physicsClientId=self._id)


@dataclass(frozen=True)
class JointLimit:
    """Limits of one joint as the URDF states them (rad, rad/s, N·m; m and m/s for prismatic)."""
    lower: float
    upper: float
    velocity: float
    effort: float


class World:
    """A headless PyBullet simulation of the robot on a flat floor."""

    def __init__(self, time_step: float = 1.0 / 240.0, urdf_path: str = URDF_PATH) -> None:
        self.time_step = time_step
        self.time = 0.0
        self.urdf_path = urdf_path
        self._p = PhysicsClient()
        p = self._p
        p.setAdditionalSearchPath(pybullet_data.getDataPath())
        p.setGravity(0, 0, -9.81)
        p.setTimeStep(time_step)
        self.plane = p.loadURDF("plane.urdf")
        # Implicit cylinders: by default PyBullet turns a URDF cylinder into a convex hull (a wheel
        # on it rolled ~2 % farther than 2πr per turn). The wheels collide as spheres of their
        # radius (the URDF): a cylinder touches the floor along a line, PyBullet split the load over
        # 2–4 points by the base's last roll, and in turns in place the wheels crept (the base
        # moved up to 15 mm per turn, unseen by odometry; now 0.1 mm).
        self.robot = p.loadURDF(urdf_path, [0, 0, 0.1], useFixedBase=False,
                                flags=pybullet.URDF_USE_INERTIA_FROM_FILE
                                | pybullet.URDF_USE_IMPLICIT_CYLINDER)
        self._joint = {}
        self._link = {}
        self.limits: dict[str, JointLimit] = {}
        for j in range(p.getNumJoints(self.robot)):
            info = p.getJointInfo(self.robot, j)
            name = info[1].decode()
            self._joint[name] = j
            self._link[info[12].decode()] = j
            self.limits[name] = JointLimit(info[8], info[9], info[11], info[10])
        # Free all motors; every driven joint gets an explicit motor below.
        for j in self._joint.values():
            p.setJointMotorControl2(self.robot, j, pybullet.VELOCITY_CONTROL, force=0)
        for link in (-1, *self._joint.values()):
            p.setCollisionFilterGroupMask(self.robot, link, ROBOT_GROUP, -1)
        self.obstacles: list[int] = []
        # Sprung casters: frictionless, and compliant so that the driven wheels carry the weight
        # (rigid casters took ~90 % of it and the wheels slipped: odometry drifted in turns).
        for name in CASTER_LINKS:
            p.changeDynamics(self.robot, self._link[name], lateralFriction=0.0,
                             rollingFriction=0.0, spinningFriction=0.0,
                             contactStiffness=5.0e4, contactDamping=3.0e3)
        for name in WHEEL_JOINTS:
            p.changeDynamics(self.robot, self._joint[name], lateralFriction=1.5)
        # Bullet's sleeping: a robot at rest (its velocities below Bullet's threshold for 2 s)
        # is not integrated until something wakes it, so an idle step costs ~5 µs instead of
        # ~90 µs (most of an idle controller's CPU). Every set-point wakes it (`_wake`): a motion
        # gives one each step, so it never sleeps while commanded, however slowly it moves.
        p.changeDynamics(self.robot, -1, activationState=pybullet.ACTIVATION_STATE_ENABLE_SLEEPING)
        self._arm_ids = [self._joint[n] for n in ARM_JOINTS]
        self._arm_forces = [self.limits[n].effort for n in ARM_JOINTS]
        self._grip_ids = [self._joint[n] for n in GRIPPER_JOINTS]
        self._wheel_ids = [self._joint[n] for n in WHEEL_JOINTS]
        self._sensed_ids = [*self._arm_ids, self._grip_ids[0], *self._wheel_ids]
        self._positions: list[float] | None = None
        self._arm_speeds: list[float] = []
        self._movable = [j for j in self._joint.values()
                         if p.getJointInfo(self.robot, j)[2] != pybullet.JOINT_FIXED]
        self._movable_names = [p.getJointInfo(self.robot, j)[1].decode() for j in self._movable]
        self.reset_arm(np.zeros(len(ARM_JOINTS)))
        self.set_gripper_target(0.0)
        self._wheel_target: tuple[float, float] | str | None = None
        self.set_wheel_velocities(0.0, 0.0)
        self.wheel_radius = 0.10
        self.wheel_separation = 0.50
        self.footprint = self._footprint()

    def _footprint(self) -> tuple[float, float, float, float]:
        """(x min, x max, y min, y max) of the base's links around base_link [m], from their
        collision shapes as loaded (the robot at the origin, facing +x)."""
        (bx, by, _), _ = self.base_link_pose()
        boxes = [self._p.getAABB(self.robot, -1 if name == "base_link" else self._link[name])
                 for name in BASE_LINKS]
        return (min(b[0][0] for b in boxes) - bx, max(b[1][0] for b in boxes) - bx,
                min(b[0][1] for b in boxes) - by, max(b[1][1] for b in boxes) - by)

    def close(self) -> None:
        self._p.disconnect()

    def _wake(self) -> None:
        """Integrate the robot again from the next step (a new set-point or pose)."""
        self._p.changeDynamics(self.robot, -1, activationState=pybullet.ACTIVATION_STATE_WAKE_UP)

    def step(self) -> None:
        self._p.stepSimulation()
        self._positions = None
        self.time += self.time_step

    def _sensed(self) -> list[float]:
        """Positions of the arm joints, the gripper finger and the wheels, read from PyBullet
        once per state of the world (the cores sample all of them every step), with the arm
        joints' velocities (`_arm_speeds`)."""
        if self._positions is None:
            states = self._p.getJointStates(self.robot, self._sensed_ids)
            self._positions = [s[0] for s in states]
            self._arm_speeds = [s[1] for s in states[:len(self._arm_ids)]]
        return self._positions

    def render(self, eye: tuple[float, float, float], target: tuple[float, float, float],
               fov_deg: float, width: int, height: int, shadow: bool = False) -> np.ndarray:
        """An RGB image (height × width × 3, uint8) from a pinhole camera at `eye` looking at
        `target` (m, z up), by PyBullet's CPU renderer (headless, no GPU): some milliseconds, so
        call it seldom; `shadow` for pictures meant for people."""
        p = self._p
        view = p.computeViewMatrix(eye, target, [0.0, 0.0, 1.0])
        projection = p.computeProjectionMatrixFOV(fov_deg, width / height, 0.05, 50.0)
        rgba = p.getCameraImage(width, height, view, projection, shadow=int(shadow),
                                lightDirection=[1.0, 1.0, 2.0],
                                renderer=pybullet.ER_TINY_RENDERER)[2]
        return np.asarray(rgba, np.uint8).reshape(height, width, 4)[:, :, :3]

    def placement(self) -> tuple[tuple[float, ...], tuple[float, ...], list[float]]:
        """Base position, base orientation (quaternion x, y, z, w) and the movable joints'
        positions: what a copy of this world needs to look the same (`show`)."""
        pos, orn = self._p.getBasePositionAndOrientation(self.robot)
        return pos, orn, [s[0] for s in self._p.getJointStates(self.robot, self._movable)]

    def show(self, placement: tuple[tuple[float, ...], tuple[float, ...], list[float]]) -> None:
        """Put the robot where `placement` (of another world) has it: for rendering a copy."""
        pos, orn, joints = placement
        self._p.resetBasePositionAndOrientation(self.robot, pos, orn)
        for j, q in zip(self._movable, joints):
            self._p.resetJointState(self.robot, j, q)
        self._positions = None
        self._wake()

    def joint_states(self) -> tuple[list[str], list[float], list[float]]:
        """Names, positions and velocities of every movable joint (rad, m; rad/s, m/s)."""
        states = self._p.getJointStates(self.robot, self._movable)
        return self._movable_names, [s[0] for s in states], [s[1] for s in states]

    # --- arm and gripper -------------------------------------------------------------------
    def reset_arm(self, q: np.ndarray) -> None:
        """Place the arm at q (rad) at rest and hold it there (start-up posture)."""
        for j, qi in zip(self._arm_ids, q):
            self._p.resetJointState(self.robot, j, float(qi))
        self._positions = None
        self.set_arm_targets(np.asarray(q, float))

    def set_arm_targets(self, q: np.ndarray, qd: np.ndarray | None = None) -> None:
        """Track joint positions (rad) with feed-forward velocities (rad/s) through stiff motors."""
        n = len(self._arm_ids)
        self._wake()
        self._p.setJointMotorControlArray(
            self.robot, self._arm_ids, pybullet.POSITION_CONTROL,
            targetPositions=np.asarray(q, float).tolist(),
            targetVelocities=[0.0] * n if qd is None else np.asarray(qd, float).tolist(),
            forces=self._arm_forces, positionGains=[0.3] * n, velocityGains=[1.0] * n)

    def arm_positions(self) -> np.ndarray:
        return np.array(self._sensed()[:len(self._arm_ids)])

    def arm_velocities(self) -> np.ndarray:
        self._sensed()
        return np.array(self._arm_speeds)

    def set_gripper_target(self, finger: float) -> None:
        """Both fingers to `finger` metres from the centre (the URDF mimic, enforced here)."""
        lim = self.limits[GRIPPER_JOINTS[0]]
        self._wake()
        self._p.setJointMotorControlArray(
            self.robot, self._grip_ids, pybullet.POSITION_CONTROL,
            targetPositions=[finger, finger], forces=[lim.effort] * 2,
            positionGains=[0.3] * 2)

    def gripper_position(self) -> float:
        return self._sensed()[len(self._arm_ids)]

    # --- base ------------------------------------------------------------------------------
    def set_wheel_velocities(self, left: float, right: float) -> None:
        """Wheel angular velocities (rad/s) through torque-limited velocity motors. A motor
        keeps its target, so the same target again (a base at rest, every step) is not sent;
        it wakes the robot all the same: a drive at constant speed gives it each step."""
        self._wake()
        if (left, right) == self._wheel_target:
            return
        self._wheel_target = (left, right)
        eff = self.limits[WHEEL_JOINTS[0]].effort
        self._p.setJointMotorControlArray(
            self.robot, self._wheel_ids, pybullet.VELOCITY_CONTROL,
            targetVelocities=[left, right], forces=[eff, eff])

    def hold_wheels(self) -> None:
        """Hold the wheels where they are (a base at rest): a velocity motor at 0 let them creep
        (0.03 rad in 2 min, the base yawing 0.3°); the next `set_wheel_velocities` drives again."""
        if self._wheel_target == HELD:
            return
        self._wheel_target = HELD
        self._wake()
        eff = self.limits[WHEEL_JOINTS[0]].effort
        self._p.setJointMotorControlArray(
            self.robot, self._wheel_ids, pybullet.POSITION_CONTROL,
            targetPositions=self.wheel_positions().tolist(), forces=[eff, eff])

    def wheel_positions(self) -> np.ndarray:
        """Unwrapped wheel angles (rad): PyBullet reports continuous joints without wrapping."""
        return np.array(self._sensed()[-len(self._wheel_ids):])

    def base_pose(self) -> tuple[float, float, float]:
        """Ground truth (x, y, yaw) of base_link in the world frame (m, rad)."""
        pos, orn = self._p.getBasePositionAndOrientation(self.robot)
        yaw = self._p.getEulerFromQuaternion(orn)[2]
        return float(pos[0]), float(pos[1]), float(yaw)

    def base_link_pose(self) -> tuple[tuple[float, float, float], tuple[float, float, float, float]]:
        """Ground-truth position (m) and quaternion (x, y, z, w) of the base_link frame in the
        world (PyBullet reports the base's inertial frame; its offset is taken out here)."""
        p = self._p
        com_pos, com_orn = p.getBasePositionAndOrientation(self.robot)
        local_pos, local_orn = p.getDynamicsInfo(self.robot, -1)[3:5]
        inv_pos, inv_orn = p.invertTransform(local_pos, local_orn)
        pos, orn = p.multiplyTransforms(com_pos, com_orn, inv_pos, inv_orn)
        return tuple(pos), tuple(orn)

    def base_twist(self) -> tuple[float, float]:
        """Ground-truth forward speed (m/s) and yaw rate (rad/s)."""
        lin, ang = self._p.getBaseVelocity(self.robot)
        yaw = self.base_pose()[2]
        return float(lin[0] * math.cos(yaw) + lin[1] * math.sin(yaw)), float(ang[2])

    def bumper_in_contact(self) -> bool:
        """True when the bumper touches anything but the floor."""
        for c in self._p.getContactPoints(bodyA=self.robot, linkIndexA=self._link[BUMPER_LINK]):
            if c[2] != self.plane:
                return True
        return False

    def add_box(self, position: tuple[float, float, float], half_extents: tuple[float, float, float],
                mass: float = 0.0, yaw: float = 0.0) -> int:
        """An obstacle (static when mass is 0), for contact tests, demos and world files."""
        p = self._p
        shape = p.createCollisionShape(pybullet.GEOM_BOX, halfExtents=half_extents)
        look = p.createVisualShape(pybullet.GEOM_BOX, halfExtents=half_extents,
                                   rgbaColor=OBSTACLE_RGBA)
        body = p.createMultiBody(mass, shape, look, position,
                                 p.getQuaternionFromEuler((0.0, 0.0, yaw)))
        self.obstacles.append(body)
        return body

    def add_cylinder(self, position: tuple[float, float, float], radius: float,
                     height: float) -> int:
        """A static upright cylinder (world files)."""
        p = self._p
        shape = p.createCollisionShape(pybullet.GEOM_CYLINDER, radius=radius, height=height)
        look = p.createVisualShape(pybullet.GEOM_CYLINDER, radius=radius, length=height,
                                   rgbaColor=OBSTACLE_RGBA)
        body = p.createMultiBody(0.0, shape, look, position)
        self.obstacles.append(body)
        return body

    def link_pose(self, name: str) -> tuple[tuple[float, float, float],
                                             tuple[float, float, float, float]]:
        """Position (m) and quaternion (x, y, z, w) of a URDF link's frame in the world."""
        state = self._p.getLinkState(self.robot, self._link[name])
        return tuple(state[4]), tuple(state[5])

    def cast_rays(self, starts: list, ends: list) -> np.ndarray:
        """For each ray from starts[i] to ends[i] (m, world), the fraction of its length at
        which it first hits something other than a robot's own links (1.0: nothing), by one
        batched PyBullet ray cast."""
        hits = self._p.rayTestBatch(starts, ends, collisionFilterMask=EVERYTHING_BUT_ROBOTS)
        return np.fromiter((h[2] if h[0] >= 0 else 1.0 for h in hits), float, len(hits))
