"""`scan` (sensor_msgs/LaserScan, frame base_scan): the simulated laser scanner of the base.

Scheduling: the sweep is cast in SLICES_PER_SCAN slices on the simulation thread (an after-step
listener at SLICES_PER_SCAN × scan_rate_hz), each slice the beams due since the last one, as a
rotating scanner takes them; so no step carries a whole scan's ray casting (a 360-beam scan is
~2.7 ms of CPU; a slice ~0.3 ms), and the finished message leaves through the process's outbox
thread. Nothing is cast while nobody subscribes to `scan`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from rclpy.node import Node
from sensor_msgs.msg import LaserScan

from acti_bringup.serving.parameters import declare_config
from acti_bringup.simulation import Simulation, stamp
from acti_motion.config_fields import ranged
from acti_sim.surroundings.scanner import LaserScanner, Scan, ScanGeometry
from acti_sim.world import World

SCAN_FRAME = "base_scan"
SLICES_PER_SCAN = 10


@dataclass
class ScanConfig:
    scan_rate_hz: float = ranged(10.0, 0.0, 50.0)       # scans per second of simulated time on `scan`; 0: no scanner
    scan_fov_deg: float = ranged(360.0, 1.0, 360.0)     # field of view, centred ahead [degree]
    scan_beams: int = ranged(360, 2, 4000)              # beams per scan
    scan_range_min: float = ranged(0.05, 0.0, 10.0)     # [m]
    scan_range_max: float = ranged(10.0, 0.1, 100.0)    # [m]; no return within it reads +inf (REP 117)
    scan_noise: float = ranged(0.0, 0.0, 1.0)           # standard deviation of the range noise [m]; 0: exact


class ScanPublisher:
    """The scanner of one hosted simulation, published while someone subscribes."""

    def __init__(self, node: Node, simulation: Simulation) -> None:
        c = self.config = declare_config(node, ScanConfig)
        if c.scan_range_min >= c.scan_range_max:
            raise ValueError(f"scan_range_min ({c.scan_range_min:g} m) must be below "
                             f"scan_range_max ({c.scan_range_max:g} m)")
        self.latest: Scan | None = None
        self.scanner: LaserScanner | None = None
        self.watched = False          # the view shows the scan: sweep without subscribers too
        if c.scan_rate_hz == 0:
            return
        self.scanner = LaserScanner(SCAN_FRAME, ScanGeometry(
            math.radians(c.scan_fov_deg), c.scan_beams, c.scan_range_min, c.scan_range_max,
            c.scan_noise), 1.0 / c.scan_rate_hz)
        self._publisher = node.create_publisher(LaserScan, "scan", 10)
        simulation.publish_at(SLICES_PER_SCAN * c.scan_rate_hz, self._sweep, self._publisher,
                              wanted=lambda: self.watched)

    def _sweep(self, world: World) -> None:
        scan = self.scanner.advance(world)
        if scan is None:
            return
        self.latest = scan
        if not self._publisher.get_subscription_count():
            return                    # swept for the view only
        g, period = self.scanner.geometry, self.scanner.period
        msg = LaserScan(angle_min=g.angle_min, angle_max=g.angle_min + g.angle_increment * (g.beams - 1),
                        angle_increment=g.angle_increment, time_increment=self.scanner.time_increment,
                        scan_time=period, range_min=g.range_min, range_max=g.range_max,
                        ranges=scan.ranges.astype("float32").tolist())
        msg.header.stamp = stamp(scan.start_time)
        msg.header.frame_id = SCAN_FRAME
        self._publisher.publish(msg)
