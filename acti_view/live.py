"""The live 3D view in a browser: viser serves the page (its client is bundled in the wheel, so
it works offline) and this module keeps the scene and the panel up to date on a thread of its
own, at its own rate, from `Reader` samples: the simulation thread never waits for it.

Scene: the robot from the URDF posed like the simulation, the floor grid, the base's odometry
path, the control point's trail, the targets of queued motions. Panel: the arm's and the base's
state; buttons from `controls.CONTROLS`.
"""
from __future__ import annotations

import logging
import math
import socket
import threading
import time
from collections import deque
from pathlib import Path
from typing import Any, Callable

import numpy as np
import rich
import viser
from viser.extras import ViserUrdf

from acti_view.controls import CONTROLS, Control, press
from acti_view.follow import EYE, LOOK_AT, RobotFollow
from acti_view.program import ProgramSource, program_markdown
from acti_view.sample import ArmPanel, BasePanel, Reader, ViewSample, state_words

TRAIL_STEP_M = 0.002          # a trail gets a point when the robot moved this far
PATH_STEP_M = 0.005
POSE_STEP = 1e-4              # rad, m: a pose that changed less is not sent again
PANEL_EVERY = 5               # frames between panel refreshes
ORANGE, BLUE, GREEN, RED = (255, 128, 20), (40, 110, 230), (30, 170, 60), (220, 40, 40)


def check_host(host: str) -> None:
    """ValueError unless a server can listen on `host` here. Checked first: viser's server
    thread fails on an address it cannot bind, and its start then waits for ever."""
    try:
        addresses = socket.getaddrinfo(host, 0, type=socket.SOCK_STREAM)
    except (socket.gaierror, UnicodeError) as e:
        raise ValueError(f"view_host {host!r} is no address: {e}") from None
    problems = []
    for family, kind, proto, _name, address in addresses:
        with socket.socket(family, kind, proto) as s:
            try:
                s.bind(address)
                return
            except OSError as e:
                problems.append(str(e))
    raise ValueError(f"view_host {host!r} is not an address of this machine: "
                     + "; ".join(dict.fromkeys(problems)))


class LiveView:
    """A viser server showing the robot; `start` serves it, `close` ends it."""

    def __init__(self, reader: Reader, cores: dict[str, Any], urdf_path: str, host: str,
                 port: int, rate_hz: float, trail_points: int,
                 log: Callable[[str], None] = print,
                 program: ProgramSource | None = None, layers: tuple = ()) -> None:
        """`layers`: more of the scene (`acti_view.surroundings.SurroundingsLayer`): each is
        added once (`add(scene)`), updated each frame (`update(scene, base pose x, y, yaw)`)
        and told whether a page is open (`watched(bool)`)."""
        self.reader = reader
        self.program = program        # the RoboLine program that runs, for its panel
        self.layers = layers
        self.cores = cores
        self.period = 1.0 / rate_hz
        self.log = log
        check_host(host)
        rich.reconfigure(quiet=True)     # viser's own box and lines: the URL goes to `log`
        logging.getLogger("websockets").setLevel(logging.WARNING)   # "server listening" …
        self.server = viser.ViserServer(host=host, port=port, label="acti_ros2", verbose=False)
        self.server.initial_camera.position = tuple(EYE)
        self.server.initial_camera.look_at = tuple(LOOK_AT)
        # the panel beside the scene, not over it (and collapsible): it hid the robot
        self.server.gui.main_panel.dock_right()
        self.follow = RobotFollow(self.server)
        scene = self.server.scene
        scene.add_grid("/floor", width=10.0, height=10.0, cell_size=0.25, section_size=1.0)
        self.robot = scene.add_frame("/robot", show_axes=False)
        for layer in layers:
            layer.add(scene)
        self.urdf = ViserUrdf(self.server, Path(urdf_path), root_node_name="/robot")
        self._joint_names = self.urdf.get_actuated_joint_names()
        self.trail: deque[np.ndarray] = deque(maxlen=trail_points)
        self.path: deque[np.ndarray] = deque(maxlen=trail_points)
        self._lines: dict[str, Any] = {}          # the trails' scene nodes
        self._watched = False
        self._restarted_at = -1                   # the sampler's count when the trails restarted
        self.frames = 0
        self._panel_text = ""
        self._shown_targets: tuple = ()
        self._shown_pose: np.ndarray | None = None
        self._build_panel()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._loop, name="acti-view", daemon=True)

    @property
    def url(self) -> str:
        return f"http://{self.server.get_host()}:{self.server.get_port()}/"

    # --- panel -------------------------------------------------------------------------------
    def _build_panel(self) -> None:
        gui = self.server.gui
        self.status = gui.add_markdown("")
        self.last_command = gui.add_markdown("*no command yet*")
        if self.program is not None:
            with gui.add_folder("Program"):
                self.program_panel = gui.add_markdown(program_markdown(None))
        for device in ("arm", "base"):
            if device not in self.cores:
                continue
            with gui.add_folder(device.capitalize()):
                for control in (c for c in CONTROLS if c.device == device):
                    button = gui.add_button(control.label,
                                            color="red" if control.method == "stop" else None)
                    button.on_click(self._on_press(control))

    def _on_press(self, control: Control) -> Callable[[Any], None]:
        def on_click(_event: Any) -> None:
            try:
                said = press(control, self.cores)
            except Exception as e:        # the page is told, the server stays up
                said = f"{control.device} {control.method} failed: {e}"
            self.last_command.content = f"last command: {said}"
            self.log(f"page: {said}")
        return on_click

    # --- updates -----------------------------------------------------------------------------
    def start(self) -> None:
        self._thread.start()

    def close(self) -> None:
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join(timeout=5.0)
        self.server.stop()

    def _loop(self) -> None:
        failed = False
        deadline = time.monotonic()
        while True:
            # a fixed rate, not a fixed pause: the time an update takes is not lost
            deadline = max(deadline + self.period, time.monotonic() - self.period)
            if self._stop.wait(max(0.0, deadline - time.monotonic())):
                return
            if not self.watching(bool(self.server.get_clients())) \
                    or self.reader.sampler.count == self._restarted_at:
                continue                    # nobody looks (costs nothing), or no fresh sample yet
            try:
                self.update(self.reader.read())
                failed = False
            except Exception as e:         # reported once per failure streak; the view goes on
                if not failed:
                    self.log(f"view update failed: {type(e).__name__}: {e}")
                failed = True

    def watching(self, watched: bool) -> bool:
        """Whether a page is open now (the world is sampled only then). The first page after a
        time nobody looked restarts the trails: nothing was recorded meanwhile, and a line from
        the last point before to the first after would cut across whatever the robot did."""
        self.reader.sampler.active = watched
        for layer in self.layers:
            layer.watched(watched)
        if watched and not self._watched:
            self._restart_trails()
        self._watched = watched
        return watched

    def _restart_trails(self) -> None:
        """Also waits for a new sample of the world: the last one is from when the last page
        closed, and its pose would start the trails where the robot was then."""
        self._restarted_at = self.reader.sampler.count
        self.trail.clear()
        self.path.clear()
        for line in self._lines.values():
            line.remove()
        self._lines.clear()

    def update(self, s: ViewSample) -> None:
        """Pose the robot, extend the trails, show the targets; refresh the panel now and then."""
        self.frames += 1
        trail_grew = _extend(self.trail, s.control_point, TRAIL_STEP_M)
        path_grew = _extend(self.path, np.array([s.odometry[0], s.odometry[1], 0.002]), PATH_STEP_M)
        targets = (tuple(map(tuple, s.arm_targets)), tuple(s.base_targets))
        cfg = np.array([s.world.joints.get(n, 0.0) for n in self._joint_names])
        x, y, z, w = s.world.base_orientation
        pose = np.concatenate([cfg, s.world.base_position, (w, x, y, z)])
        posed = self._shown_pose is not None and np.max(np.abs(pose - self._shown_pose)) < POSE_STEP
        scene = self.server.scene
        with self.server.atomic():
            if not posed:                  # a robot at rest costs nothing
                self._shown_pose = pose
                self.robot.position = s.world.base_position
                self.robot.wxyz = (w, x, y, z)
                self.urdf.update_cfg(cfg)
            for name, points, grew, color in (("/trail/control_point", self.trail, trail_grew, ORANGE),
                                              ("/trail/odometry", self.path, path_grew, BLUE)):
                if grew and len(points) >= 2:
                    self._lines[name] = _polyline(scene, name, points, color)
            if targets != self._shown_targets:      # sent only when they change
                self._shown_targets = targets
                _points(scene, "/targets/arm", s.arm_targets, GREEN, 0.03)
                _points(scene, "/targets/base", [(x_, y_, 0.01) for x_, y_ in s.base_targets],
                        RED, 0.06)
            for layer in self.layers:
                layer.update(scene, (*s.world.base_position[:2], 2 * math.atan2(z, w)))
        self.follow.moved(s.world.base_position)
        if self.frames % PANEL_EVERY == 1:
            text = panel_text(s.arm, s.base)
            if text != self._panel_text:
                self.status.content = self._panel_text = text
            if self.program is not None:
                shown = program_markdown(self.program())
                if shown != self.program_panel.content:
                    self.program_panel.content = shown


def panel_text(arm: ArmPanel | None, base: BasePanel | None) -> str:
    """The panel as markdown: the arm's state word, queue, alarms, motion; the base's state."""
    lines = []
    if arm is not None:
        motion = (f"#{arm.motion_id} {arm.motion_label} {100 * arm.progress:.0f} %"
                  if arm.motion_id else "none")
        lines += ["#### Arm", f"- state: {state_words(arm.state)}",
                  f"- queued: {arm.queue_length}", f"- motion: {motion}",
                  f"- alarms: {'; '.join(arm.alarms) if arm.alarms else 'none'}", ""]
    if base is not None:
        x, y, th = base.position_mm_deg
        lines += ["#### Base", f"- state: 0x{base.state:03X} {base.state_string}",
                  f"- position: x {round(x):d} mm, y {round(y):d} mm, θ {round(th, 1) + 0.0:.1f}°",
                  f"- battery: {base.battery_v:.1f} V", f"- queued: {base.queue_length}"]
    return "\n".join(lines)


def _extend(trail: deque, point: np.ndarray, step: float) -> bool:
    """Append the point when it is `step` away from the last one; whether it was."""
    if trail and np.linalg.norm(trail[-1] - point) < step:
        return False
    trail.append(np.asarray(point, float))
    return True


def _polyline(scene: Any, name: str, points: deque, color: tuple[int, int, int]) -> Any:
    p = np.asarray(points, np.float32)
    return scene.add_line_segments(name, np.stack([p[:-1], p[1:]], axis=1), color, thickness=0.006)


def _points(scene: Any, name: str, points: list, color: tuple[int, int, int],
            size: float) -> None:
    p = np.asarray(points, np.float32).reshape(-1, 3)
    if not len(p):
        scene.add_point_cloud(name, np.zeros((1, 3), np.float32), color, point_size=size,
                              visible=False)
        return
    scene.add_point_cloud(name, p, color, point_size=size, point_shape="circle")
