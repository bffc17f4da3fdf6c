"""A camera looking at the work cell: `~/camera/image_raw` (rgb8) and `~/camera/camera_info`
at `camera_rate_hz` of simulated time (0, the default: off).

PyBullet's renderer takes tens of milliseconds a frame and holds the GIL all along, which would
stall every service of the process: frames are rendered in a process of their own, by a copy
of the world that the simulation thread poses (`World.placement`, microseconds) once a frame.
A frame asked for while the last one is still rendering is skipped. What the camera costs the
simulation: bench/bench_ros_graph.py.

The camera stands still in the world: its optical frame (z forward, x right, y down) hangs off
`odom`, the world frame at start, on /tf_static."""
from __future__ import annotations

import math
import multiprocessing
import os
import signal
import threading
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np
from rclpy.node import Node
from sensor_msgs.msg import CameraInfo, Image
from tf2_msgs.msg import TFMessage

from acti_bringup.serving.parameters import declare_config
from acti_bringup.visual.transforms import link_transform, static_tf_publisher
from acti_motion.executor import MotionExecutor
from acti_motion.arm.poses import quaternion_xyzw
from acti_motion.config_fields import ranged
from acti_motion.link_poses import LinkTransform
from acti_sim.surroundings.worldfile import WorldSpec, build_world
from acti_sim.world import World

PARENT_FRAME = "odom"
OPTICAL_FRAME = "camera_optical_frame"
MAX_PIXELS = 1920 * 1080


@dataclass
class CameraConfig:
    camera_rate_hz: float = ranged(0.0, 0.0, 2000.0)   # images per second of simulated time on ~/camera/image_raw; 0: no camera (rendering costs CPU)
    camera_width: int = ranged(320, 1, MAX_PIXELS)     # image width [px]
    camera_height: int = ranged(240, 1, MAX_PIXELS)    # image height [px]
    camera_fov_deg: float = ranged(60.0, 0.1, 179.9)   # vertical field of view [degree]
    camera_eye: tuple[float, ...] = (1.6, -1.3, 1.2)      # camera position in odom (the world at start) [m]
    camera_target: tuple[float, ...] = (0.2, 0.0, 0.65)   # the point it looks at, in odom [m]


def check_camera(c: CameraConfig) -> None:
    """ValueError that says which camera parameter is wrong."""
    numbers = [c.camera_rate_hz, c.camera_fov_deg, *c.camera_eye, *c.camera_target]
    if not all(math.isfinite(x) for x in numbers) or c.camera_rate_hz < 0:
        raise ValueError("camera_rate_hz must be >= 0 and the camera values finite")
    if not (0 < c.camera_width and 0 < c.camera_height
            and c.camera_width * c.camera_height <= MAX_PIXELS):
        raise ValueError(f"camera_width × camera_height must be positive, at most {MAX_PIXELS} px")
    if len(c.camera_eye) != 3 or len(c.camera_target) != 3:
        raise ValueError("camera_eye and camera_target are x, y, z")
    view = np.subtract(c.camera_target, c.camera_eye)
    if np.linalg.norm(np.cross(view, [0.0, 0.0, 1.0])) < 1e-6 * max(1.0, np.linalg.norm(view)):
        raise ValueError("camera_target must differ from camera_eye, and not be straight above "
                         "or below it")


def optical_frame(eye: tuple[float, ...], target: tuple[float, ...]) -> LinkTransform:
    """The optical frame (z towards the target, x right, y down; the image upright) in odom."""
    z = np.subtract(target, eye) / np.linalg.norm(np.subtract(target, eye))
    x = np.cross(z, [0.0, 0.0, 1.0])
    x /= np.linalg.norm(x)
    rotation = np.column_stack([x, np.cross(z, x), z])
    q = quaternion_xyzw(rotation)
    return LinkTransform(PARENT_FRAME, OPTICAL_FRAME, tuple(float(v) for v in eye),
                         tuple(float(v) for v in q))


def camera_info(width: int, height: int, fov_deg: float) -> CameraInfo:
    """Intrinsics of PyBullet's projection: square pixels, principal point at the centre."""
    f = (height / 2) / math.tan(math.radians(fov_deg) / 2)
    cx, cy = width / 2 - 0.5, height / 2 - 0.5
    info = CameraInfo(width=width, height=height, distortion_model="plumb_bob")
    info.d = [0.0] * 5
    info.k = [f, 0.0, cx, 0.0, f, cy, 0.0, 0.0, 1.0]
    info.r = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
    info.p = [f, 0.0, cx, 0.0, 0.0, f, cy, 0.0, 0.0, 0.0, 1.0, 0.0]
    info.header.frame_id = OPTICAL_FRAME
    return info


def render_frames(requests: Any, frames: Any, urdf_path: str, config: CameraConfig,
                  surroundings: WorldSpec = WorldSpec()) -> None:
    """The render process: pose a copy of the world as asked, send back the RGB bytes; ends
    when the simulation's end of the pipe closes. SIGINT is the host's to handle. It runs at
    ordinary niceness (0), not the control loop's raised one: its frames may wait, the robot not."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    os.setpriority(os.PRIO_PROCESS, 0, 0)
    world = World(urdf_path=urdf_path)
    build_world(world, surroundings)          # the world file's obstacles in the picture too
    c = config
    try:
        while True:
            world.show(requests.recv())
            frames.send_bytes(world.render(c.camera_eye, c.camera_target, c.camera_fov_deg,
                                           c.camera_width, c.camera_height).tobytes())
    except (EOFError, OSError):
        pass
    finally:
        world.close()


class SimCamera:
    """Publishes the work-cell camera when `camera_rate_hz` > 0."""

    def __init__(self, node: Node, executor: MotionExecutor, now: Callable[[], Any],
                 surroundings: WorldSpec = WorldSpec()) -> None:
        self.config = c = declare_config(node, CameraConfig)
        check_camera(c)
        if c.camera_rate_hz == 0:
            return
        self._now, self._executor, self._log = now, executor, node.get_logger()
        self._info = camera_info(c.camera_width, c.camera_height, c.camera_fov_deg)
        self._image = node.create_publisher(Image, "~/camera/image_raw", 2)
        self._info_pub = node.create_publisher(CameraInfo, "~/camera/camera_info", 2)
        self._static = static_tf_publisher(node)
        self._static.publish(TFMessage(transforms=[
            link_transform(now(), optical_frame(c.camera_eye, c.camera_target))]))
        spawn = multiprocessing.get_context("spawn")
        requests, self._requests = spawn.Pipe(duplex=False)
        self._frames, frames = spawn.Pipe(duplex=False)
        spawn.Process(target=render_frames, name="acti-camera", daemon=True,
                      args=(requests, frames, executor.world.urdf_path, c, surroundings)).start()
        requests.close()
        frames.close()
        self._stamp: Any = None                 # of the frame being rendered; None: idle
        threading.Thread(target=self._publish_frames, name="acti-camera-publish",
                         daemon=True).start()
        executor.after_step(self._ask, every=executor.steps_per_period(c.camera_rate_hz))

    def _ask(self, world: World) -> None:
        """Simulation thread: hand the renderer this instant, unless it is still busy (or gone)."""
        if self._stamp is None:
            self._stamp = self._now()
            try:
                self._requests.send(world.placement())
            except OSError:
                pass                                # gone: _publish_frames says so

    def _publish_frames(self) -> None:
        """Receive and publish frames until the render process ends."""
        self._publish_until_the_renderer_ends()
        self._stamp = "gone"                        # ask no more
        if self._executor.running:
            self._log.error("camera: the render process ended; no more images")

    def _publish_until_the_renderer_ends(self) -> None:
        c = self.config
        while True:
            try:
                rgb = self._frames.recv_bytes()
            except (EOFError, OSError):
                return
            image = Image(height=c.camera_height, width=c.camera_width, encoding="rgb8",
                          step=3 * c.camera_width, data=rgb)
            image.header.stamp = self._info.header.stamp = self._stamp
            image.header.frame_id = OPTICAL_FRAME
            self._stamp = None
            if not self._executor.running:          # the host is shutting down
                return
            self._image.publish(image)
            self._info_pub.publish(self._info)
