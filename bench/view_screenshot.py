"""docs/live_view.png: the live view of a running main job, as a browser shows it, while the
base cruises and the arm works through queued moves (its trail, the odometry path and the
queued targets in view).

    python bench/view_screenshot.py [OUT.png]
"""
from __future__ import annotations

import os
import sys

from common import RosClient, ok, save_page, view_page

from acti_msgs import srv
from acti_msgs.msg import VehiclePoint

ARM, BASE = "/acti_middle_node/", "/vehicle_node/"
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def main() -> None:
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "docs", "live_view.png")
    ros = RosClient()
    with view_page(ros, 1000, 640) as (_job, browser):
        ok(ros.call(srv.VehicleSetPower, BASE + "set_power", on_off=True))
        ok(ros.call(srv.VehicleSetServo, BASE + "set_servo", on_off=True))
        for x, y in ((-200.0, 600.0), (-700.0, 700.0), (-1100.0, 400.0)):
            ok(ros.call(srv.VehicleMoveCruiseAbs, BASE + "move_cruise_abs",
                        cruise_point=VehiclePoint(x=x, y=y)))
        ok(ros.call(srv.ServoON, ARM + "servo_on"))
        ok(ros.call(srv.SetSpeedJoint, ARM + "set_speed_joint", spd_ratio=15))
        for q in ([40, 50, 0, -60, 0, 50, 0], [-30, 60, 20, -40, 0, 60, 0],
                  [20, 30, 0, -90, 0, 60, 0], [0, 45, 0, -60, 0, 60, 0]):
            ok(ros.call(srv.MovePTPJointAbs, ARM + "move_ptp_joint_abs",
                        joint_points=[float(v) for v in q]))
        # half-way along the cruise: trails, path and the remaining targets are in view
        assert ros.spin_until(lambda: ros.call(srv.VehicleGetPosition, BASE + "get_position")
                              .pos.x < -400.0, 120.0)
        save_page(browser, out)
    ros.close()
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
