"""A picture of the world as a PNG, from PyBullet's CPU renderer (no GPU, no browser, no ROS)."""
from __future__ import annotations

import matplotlib.image as mpimg

from acti_sim.world import World

EYE = (2.3, -1.9, 1.5)         # m, world frame: in front of the robot, to its right, above
TARGET = (0.15, 0.0, 0.6)


def write_png(world: World, path: str, width: int = 800, height: int = 600,
              eye: tuple[float, float, float] = EYE,
              target: tuple[float, float, float] = TARGET) -> None:
    """Render the world as it is now and write it to `path`."""
    mpimg.imsave(path, world.render(eye, target, 45.0, width, height, shadow=True))
