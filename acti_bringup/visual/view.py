"""The live browser view in the main job: node `acti_view` holds its parameters and wires the
ROS-free `acti_view.live.LiveView` to the cores and the world of the hosted simulation."""
from __future__ import annotations

import math
from dataclasses import dataclass

from rclpy.node import Node

from acti_bringup.serving.parameters import declare_config
from acti_bringup.simulation import Simulation
from acti_motion.arm.core import ArmCore
from acti_motion.vehicle.core import VehicleCore
from acti_sim.world import URDF_PATH
from acti_view.live import LiveView
from acti_view.sample import Reader, WorldSampler


@dataclass
class ViewConfig:
    view_enabled: bool = True         # serve the live 3D view in a browser
    view_host: str = "127.0.0.1"      # address the view listens on (127.0.0.1: this machine only)
    view_port: int = 8080             # port of the view; the next free one when in use; 0: any free one
    view_rate_hz: float = 25.0        # scene updates per second while a page is open [Hz]
    view_trail_points: int = 2000     # points kept in the control-point trail and the odometry path


class ViewNode(Node):
    """`acti_view`: serves the view of the arm and base of `simulation` (when enabled)."""

    def __init__(self, simulation: Simulation, arm: ArmCore, vehicle: VehicleCore) -> None:
        super().__init__("acti_view")
        self.config = c = declare_config(self, ViewConfig)
        self.view: LiveView | None = None
        if not c.view_enabled:
            self.get_logger().info("live view off (view_enabled:=false)")
            return
        if not 0 <= c.view_port < 65536 or not 0 < c.view_rate_hz < math.inf \
                or c.view_trail_points < 2:
            raise ValueError(f"view_port must be 0 … 65535 (is {c.view_port}), view_rate_hz > 0 "
                             f"and finite (is {c.view_rate_hz}), view_trail_points ≥ 2 "
                             f"(is {c.view_trail_points})")
        every = max(1, round(simulation.config.rate_hz / c.view_rate_hz))
        reader = Reader(WorldSampler(simulation.executor, every), arm, vehicle)
        self.view = LiveView(reader, {"arm": arm, "base": vehicle}, URDF_PATH, c.view_host,
                             c.view_port, c.view_rate_hz, c.view_trail_points,
                             log=self.get_logger().info)
        self.view.start()
        self.get_logger().info(f"live view: {self.view.url}")

    def destroy_node(self) -> None:
        if self.view is not None:
            self.view.close()
        super().destroy_node()
