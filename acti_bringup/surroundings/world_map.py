"""`map` (nav_msgs/OccupancyGrid, transient local): the world file's obstacles rasterised at
`map_resolution`, in the map frame (position_frame), published once at start-up. The map-server
pair (.yaml + .pgm) of the same grid: `python -m acti_sim.surroundings.save_map`."""
from __future__ import annotations

from dataclasses import dataclass

from nav_msgs.msg import OccupancyGrid
from rclpy.node import Node

from acti_bringup.serving.parameters import declare_config
from acti_bringup.simulation import Simulation
from acti_bringup.visual.transforms import LATCHED_QOS
from acti_motion.config_fields import ranged
from acti_sim.surroundings.occupancy import Grid, rasterise


@dataclass
class MapConfig:
    map_resolution: float = ranged(0.05, 0.01, 1.0)   # cell size of `map` [m]


def grid_message(grid: Grid, frame: str, stamp) -> OccupancyGrid:
    msg = OccupancyGrid()
    msg.header.frame_id, msg.header.stamp = frame, stamp
    info = msg.info
    info.map_load_time = stamp
    info.resolution = grid.resolution
    info.width, info.height = grid.width, grid.height
    info.origin.position.x, info.origin.position.y = grid.origin
    info.origin.orientation.w = 1.0
    msg.data = grid.cells.ravel().tolist()
    return msg


class MapPublisher:
    """The world's map, latched."""

    def __init__(self, node: Node, simulation: Simulation, frame: str) -> None:
        self.config = declare_config(node, MapConfig)
        self.grid = rasterise(simulation.surroundings, self.config.map_resolution)
        self._publisher = node.create_publisher(OccupancyGrid, "map", LATCHED_QOS)
        self._publisher.publish(grid_message(self.grid, frame, simulation.now()))
