"""The page's camera stays on the robot: while "Follow the robot" is ticked (the default), every
page's camera moves with the base (by the base's displacement: the angle and distance the person
chose are kept); "Frame the robot" puts the camera back at the default view of the robot, where
it is now. A page that opens is framed on the robot, not on the world's origin."""
from __future__ import annotations

from typing import Any

import numpy as np

EYE = np.array([1.7, -1.8, 1.3])          # the default camera, relative to the base [m]
LOOK_AT = np.array([0.2, 0.0, 0.5])       # … and the point it looks at
MOVE_STEP_M = 1e-3                         # a smaller displacement does not move the cameras


class RobotFollow:
    """The follow toggle and the frame button of the panel, and the cameras they move."""

    def __init__(self, server: Any) -> None:
        self.server = server
        self.base: np.ndarray = np.zeros(3)      # where the cameras were last put relative to
        gui = server.gui
        self.toggle = gui.add_checkbox("Follow the robot", initial_value=True)
        self.button = gui.add_button("Frame the robot")
        self.button.on_click(lambda _event: self.frame(self.server.get_clients().values()))
        server.on_client_connect(lambda client: self.frame([client]))

    def frame(self, clients: Any) -> None:
        """The default view of the robot where it is now, on each of `clients`."""
        for client in clients:
            with client.atomic():
                client.camera.position = tuple(self.base + EYE)
                client.camera.look_at = tuple(self.base + LOOK_AT)

    def moved(self, base_position: Any) -> None:
        """The base is at `base_position`: while following, every camera moves as far."""
        base = np.asarray(base_position, float)
        shift = base - self.base
        if np.max(np.abs(shift)) < MOVE_STEP_M:
            return
        self.base = base
        if not self.toggle.value:
            return
        for client in self.server.get_clients().values():
            try:
                eye, target = client.camera.position, client.camera.look_at
            except AssertionError:      # viser: its page has not told its camera yet
                continue
            with client.atomic():
                client.camera.position = tuple(np.asarray(eye) + shift)
                client.camera.look_at = tuple(np.asarray(target) + shift)
