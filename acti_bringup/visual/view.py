"""The live browser view in the main job: node `acti_view` holds its parameters and wires the
ROS-free `acti_view.live.LiveView` to the cores and the world of the hosted simulation."""
from __future__ import annotations

from dataclasses import dataclass

from rclpy.node import Node

from acti_bringup.serving.parameters import declare_config
from acti_bringup.simulation import Simulation
from acti_motion.config_fields import RATE_RANGE_HZ, ranged
from acti_motion.arm.core import ArmCore
from acti_motion.vehicle.core import VehicleCore
from acti_sim.world import URDF_PATH
from acti_bringup.surroundings.scan import ScanPublisher
from acti_view.live import LiveView
from acti_view.program import ProgramSource
from acti_view.surroundings import SurroundingsLayer
from acti_view.sample import Reader, WorldSampler


@dataclass
class ViewConfig:
    view_enabled: bool = True         # serve the live 3D view in a browser
    view_host: str = "127.0.0.1"      # address the view listens on (127.0.0.1: this machine only)
    # port of the view; the next free one when in use; 0: any free one
    view_port: int = ranged(8080, 0, 65535)
    # scene updates per second while a page is open [Hz]
    view_rate_hz: float = ranged(25.0, *RATE_RANGE_HZ)
    # points kept in the control-point trail and the odometry path
    view_trail_points: int = ranged(2000, 2, 1_000_000)


class ViewNode(Node):
    """`acti_view`: serves the view of the arm and base of `simulation` (when enabled)."""

    def __init__(self, simulation: Simulation, arm: ArmCore, vehicle: VehicleCore,
                 program: ProgramSource | None = None,
                 scan: ScanPublisher | None = None) -> None:
        super().__init__("acti_view")
        self.config = c = declare_config(self, ViewConfig)
        self.view: LiveView | None = None
        if not c.view_enabled:
            self.get_logger().info("live view off (view_enabled:=false)")
            return
        every = max(1, round(simulation.config.rate_hz / c.view_rate_hz))
        reader = Reader(WorldSampler(simulation.executor, every), arm, vehicle)
        scanner = scan.scanner if scan is not None else None
        surroundings = SurroundingsLayer(
            simulation.surroundings, scanner, lambda: scan.latest if scan is not None else None,
            vehicle, simulation.world.footprint,
            on_watch=lambda watched: setattr(scan, "watched", watched) if scan is not None else None)
        self.view = LiveView(reader, {"arm": arm, "base": vehicle}, URDF_PATH, c.view_host,
                             c.view_port, c.view_rate_hz, c.view_trail_points,
                             log=self.get_logger().info, program=program,
                             layers=(surroundings,))
        self.view.start()
        self.get_logger().info(f"live view: {self.view.url}")

    def destroy_node(self) -> None:
        if self.view is not None:
            self.view.close()
        super().destroy_node()
