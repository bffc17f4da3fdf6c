"""The simulation a process hosts: one PyBullet world and one motion-queue executor, with the
topics that belong to the world as a whole (clock, joint_states, robot_description, the links'
TF and the camera).

Every topic is relative, so each robot of a fleet (`-r __ns:=/robotN`) publishes its own world's
time, joints and transforms in its namespace: /robotN/clock, /robotN/joint_states, /robotN/tf …
(/clock, /tf … alone)."""
from __future__ import annotations

import os
import sys
from dataclasses import dataclass
from typing import Callable

import rclpy
from builtin_interfaces.msg import Time
from rclpy.node import Node
from rclpy.publisher import Publisher
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState

from acti_bringup.visual.camera import SimCamera
from acti_bringup.serving.parameters import declare_config
from acti_bringup.recording.job import JobRecording
from acti_bringup.priority import (FIFO_RANGE, NICE_RANGE, check_fifo_priority, freeze_heap,
                                   set_fifo, set_niceness)
from acti_bringup.visual.robot_graph import RobotGraph
from acti_bringup.serving.spinning import Planes, build_or_exit, init, wait_for_signal
from acti_bringup.serving.waiting import end_goals
from acti_motion.config_fields import ranged
from acti_motion.executor import MotionExecutor
from acti_sim.surroundings.worldfile import WorldSpec, build_world, load_world
from acti_sim.world import ROOT, World

SWITCH_INTERVAL_S = 2e-4
# control rates PyBullet's robot keeps stable (10 Hz: 100 ms steps) and the 2-core machine keeps
# up with (2 kHz) [Hz]
RATE_RANGE_HZ = (10.0, 2000.0)


DEFAULT_WORLD = "config/worlds/empty.yaml"


@dataclass
class SimulationConfig:
    # the world file: static obstacles (docs/world.md), a path (relative: to the project's
    # directory first, then to the working directory)
    world: str = DEFAULT_WORLD
    # physics and control rate [Hz] (250: a 4 ms cycle)
    rate_hz: float = ranged(250.0, *RATE_RANGE_HZ)
    # simulated seconds per wall second (0: as fast as it can)
    real_time_factor: float = ranged(1.0, 0.0, 100.0)
    # joint_states (and the links' TF) publication rate [Hz]
    joint_state_rate_hz: float = ranged(50.0, 0.1, RATE_RANGE_HZ[1])
    # rate of the simulated time on `clock` (/clock, or /<namespace>/clock) [Hz]; 0: not published
    clock_rate_hz: float = ranged(100.0, 0.0, RATE_RANGE_HZ[1])
    # niceness of the process's threads, -20 … 19 (lower runs first: the control loop before
    # the clients on a busy machine); below 0 needs CAP_SYS_NICE (root), else it is kept as is
    nice: int = ranged(-10, *NICE_RANGE)
    # SCHED_FIFO priority of the simulation (control loop) thread, 1 … 99; 0 (the default):
    # ordinary scheduling. Opt-in: a loop that falls behind steps without sleeping, and at FIFO
    # it then keeps a core from every ordinary thread (two 4x-real-time jobs on a busy 2-core
    # machine starved a service call for 30 s). Needs CAP_SYS_NICE (root); not applied when
    # real_time_factor is 0
    control_fifo_priority: int = ranged(0, *FIFO_RANGE)


def world_path(path: str) -> str:
    """A relative world file path is looked for in the project's directory first (the shipped
    config/worlds/), then where the process was started."""
    if os.path.isabs(path):
        return path
    shipped = os.path.join(ROOT, path)
    return shipped if os.path.exists(shipped) else os.path.abspath(path)


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
        set_niceness(c.nice, node.get_logger().warning)
        check_fifo_priority(c.control_fifo_priority)       # here, not on the simulation thread
        self._log = node.get_logger()
        self.recording = JobRecording(node)
        self.world = World(time_step=1.0 / c.rate_hz)
        self.surroundings: WorldSpec = load_world(world_path(c.world))
        build_world(self.world, self.surroundings)
        self.executor = MotionExecutor(self.world, c.real_time_factor, alive=node.context.ok)
        if c.clock_rate_hz > 0:
            self._clock = node.create_publisher(Clock, "clock", 10)
            self.publish_at(c.clock_rate_hz, self._publish_clock, self._clock)
        self._joints = node.create_publisher(JointState, "joint_states", 10)
        self.publish_at(c.joint_state_rate_hz, self._publish_joint_states, self._joints)
        self.graph = RobotGraph(node, self.world.urdf_path, c.joint_state_rate_hz, self.now,
                                self.publish_at)
        self.camera = SimCamera(node, self.executor, self.now, self.surroundings)

    def publish_at(self, rate_hz: float, publish: Callable[[World], None],
                   *publishers: Publisher, wanted: Callable[[], bool] = lambda: False) -> None:
        """Run publish(world) on the simulation thread at about rate_hz while one of `publishers`
        has a subscriber (or `wanted()` says so: the view shows it). Building messages nobody
        receives was most of an idle robot's Python work; a volatile topic without subscribers
        shows nothing, so skipping it changes nothing."""
        def received() -> bool:
            return any(p.get_subscription_count() for p in publishers) or wanted()

        def listened(world: World) -> None:
            if received():
                publish(world)
        self.executor.after_step(listened, every=self.executor.steps_per_period(rate_hz),
                                 on_time=received)

    def _schedule_control_loop(self) -> None:
        """On the simulation thread (and the outbox's, which sends the loop's messages):
        real-time scheduling when the simulation keeps time."""
        priority = self.config.control_fifo_priority
        if priority and self.config.real_time_factor == 0:
            self._log.info("control_fifo_priority not applied: real_time_factor 0 runs the "
                           "simulation as fast as it can")
            return
        set_fifo(priority, self._log.warning)

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
        theirs (`acti_bringup.serving.spinning`)."""
        planes = Planes()
        planes.add("control", nodes)
        helpers = [getattr(n, plane) for plane in ("motion", "goals") for n in nodes
                   if hasattr(n, plane)]
        for helper in helpers:
            planes.add(helper.plane, [helper])
        self.recording.introspect([*nodes, *helpers])
        freeze_heap()
        self.executor.start(prepare=self._schedule_control_loop)
        planes.outbox.put(self._schedule_control_loop)       # it carries the loop's messages
        planes.start()
        nodes[0].get_logger().info(ready_banner(nodes))
        try:
            wait_for_signal(lambda: planes.serving() and not self.executor.failed)
        finally:
            end_goals(helpers)
            self.executor.shutdown()
            planes.stop()
            for n in (*helpers, *nodes):
                n.destroy_node()
            self.world.close()
            rclpy.try_shutdown()
            self.recording.stop()
        for error in planes.errors():
            raise error
        if self.executor.failed:
            raise self.executor.error


def ready_banner(nodes: tuple[Node, ...]) -> str:
    """The line that says the job serves: its nodes, the live view's URL (the port it took),
    how to stop it."""
    names = ", ".join(n.get_fully_qualified_name() for n in nodes)
    urls = [n.view.url for n in nodes if getattr(n, "view", None) is not None]
    view = f" | live view: {urls[0]}" if urls else ""
    return f"READY: {names} serving{view} | Ctrl-C to stop"


def run_alone(node_class: type, args: list[str] | None = None) -> None:
    """`python -m <node>`: one node with a simulation of its own, until SIGINT/SIGTERM."""
    init(sys.argv if args is None else args)
    node = build_or_exit(node_class, node_class.__module__.split(".")[0],
                         f"{node_class.__module__}:{node_class.__name__}")
    node.simulation.spin(node)
