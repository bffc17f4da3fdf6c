"""docs/room.png: the live view of a main job in config/worlds/room.yaml, as a browser shows it,
while the base backs up toward the west wall: the room's obstacles, the latest laser scan (magenta
points), the caution (yellow) and stop (red) zones ahead of the base, the state in the panel.

    python bench/room_screenshot.py [OUT.png]
"""
from __future__ import annotations

import os
import sys

from common import RosClient, ok, save_page, view_page

from acti_msgs import srv
from acti_msgs.msg import VehicleVelocity

BASE = "/vehicle_node/"
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def main() -> None:
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "docs", "room.png")
    ros = RosClient()
    with view_page(ros, 1100, 700, "world:=config/worlds/room.yaml") as (_job, browser):
        ok(ros.call(srv.VehicleSetPower, BASE + "set_power", on_off=True))
        ok(ros.call(srv.VehicleSetServo, BASE + "set_servo", on_off=True))
        ok(ros.call(srv.VehicleSetVelocity, BASE + "set_velocity",
                    vel=VehicleVelocity(translation=200.0, rotation=45.0)))
        ok(ros.call(srv.VehicleMoveForward, BASE + "move_forward", x=-3000.0))
        # the wall in the caution zone behind it, not yet stopped: the zones are drawn while
        # it moves (the wall's face at -2.0 m, the base's back 0.3 m behind base_link)
        assert ros.spin_until(lambda: ros.call(srv.VehicleGetPosition, BASE + "get_position")
                              .pos.x < -950.0, 120.0)
        save_page(browser, out)
    ros.close()
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
