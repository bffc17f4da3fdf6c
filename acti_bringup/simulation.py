"""The simulation a process hosts: one PyBullet world and one motion-queue executor, with the
topics that belong to the world as a whole (/clock, joint_states, robot_description, the links'
TF and the camera)."""
from __future__ import annotations

import sys
from dataclasses import dataclass

import rclpy
from builtin_interfaces.msg import Time
from rclpy.node import Node
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState

from acti_bringup.camera import SimCamera
from acti_bringup.parameters import declare_config
from acti_bringup.robot_graph import RobotGraph
from acti_bringup.spinning import Planes, init, wait_for_signal
from acti_motion.executor import MotionExecutor
from acti_sim.world import World

SWITCH_INTERVAL_S = 2e-4


@dataclass
class SimulationConfig:
    rate_hz: float = 250.0              # physics and control rate [Hz] (250: a 4 ms cycle)
    real_time_factor: float = 1.0       # simulated seconds per wall second (0: as fast as it can)
    joint_state_rate_hz: float = 50.0   # joint_states publication rate [Hz]


def stamp(node_time: float) -> Time:
    sec = int(node_time)
    return Time(sec=sec, nanosec=int((node_time - sec) * 1e9))


class Simulation:
    """World + executor, created from the parameters of the node that hosts it."""

    def __init__(self, node: Node) -> None:
        self.config = c = declare_config(node, SimulationConfig)
        # Service threads wait for the GIL while the simulation thread computes; a short switch
        # interval bounds that wait (the default 5 ms would dominate every round trip).
        sys.setswitchinterval(SWITCH_INTERVAL_S)
        if c.rate_hz <= 0 or c.real_time_factor < 0 or c.joint_state_rate_hz <= 0:
            raise ValueError("rate_hz and joint_state_rate_hz must be > 0, real_time_factor >= 0")
        self.world = World(time_step=1.0 / c.rate_hz)
        self.executor = MotionExecutor(self.world, c.real_time_factor, alive=node.context.ok)
        self._clock = node.create_publisher(Clock, "/clock", 10)
        self._joints = node.create_publisher(JointState, "joint_states", 10)
        self.executor.after_step(self._publish_clock)
        joint_state_every = max(1, round(c.rate_hz / c.joint_state_rate_hz))
        self.executor.after_step(self._publish_joint_states, every=joint_state_every)
        self.graph = RobotGraph(node, self.executor, joint_state_every, self.now)
        self.camera = SimCamera(node, self.executor, self.now)

    def now(self) -> Time:
        return stamp(self.world.time)

    def _publish_clock(self, world: World) -> None:
        self._clock.publish(Clock(clock=self.now()))

    def _publish_joint_states(self, world: World) -> None:
        names, pos, vel = world.joint_states()
        msg = JointState(name=names, position=pos, velocity=vel)
        msg.header.stamp = self.now()
        self._joints.publish(msg)

    def spin(self, *nodes: Node) -> None:
        """Run the simulation and serve the nodes until SIGINT/SIGTERM, then clean up: each node
        on the control plane, its `motion` and `goals` plane nodes (a device node has them) on
        theirs (`acti_bringup.spinning`)."""
        planes = Planes()
        planes.add("control", nodes)
        helpers = [getattr(n, plane) for plane in ("motion", "goals") for n in nodes
                   if hasattr(n, plane)]
        for helper in helpers:
            planes.add(helper.plane, [helper])
        self.executor.start()
        planes.start()
        try:
            wait_for_signal(planes.serving)
        finally:
            self.executor.shutdown()
            planes.stop()
            for n in (*helpers, *nodes):
                n.destroy_node()
            self.world.close()
            rclpy.try_shutdown()
        for error in planes.errors():
            raise error


def run_alone(node_class: type, args: list[str] | None = None) -> None:
    """`python -m <node>`: one node with a simulation of its own, until SIGINT/SIGTERM."""
    init(sys.argv if args is None else args)
    node = node_class()
    node.simulation.spin(node)
