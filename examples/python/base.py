"""The mobile base from Python: power and servo on, 500 mm forward and a wait for it, then three
cruise points that join one smooth path (each call answers that path's motion id), a wait with
the pose as it goes, where the base is then, servo and power off.

Run it beside `make run`, in a shell that sourced tools/env.sh: python examples/python/base.py"""
from acti_client import Client

from acti_msgs.action import VehicleWaitMotion
from acti_msgs.msg import VehiclePoint
from acti_msgs.srv import (VehicleGetPosition, VehicleGetState, VehicleMoveCruiseAbs,
                           VehicleMoveForward, VehicleSetPower, VehicleSetServo)

BASE = "/vehicle_node"
CRUISE = [(1000.0, 300.0), (1500.0, 0.0), (2000.0, 0.0)]     # [mm], in the position frame


def main() -> None:
    base = Client("base_example")
    base.call(VehicleSetPower, f"{BASE}/set_power", on_off=True)
    base.call(VehicleSetServo, f"{BASE}/set_servo", on_off=True)
    state = base.call(VehicleGetState, f"{BASE}/get_state")
    print(f"state 0x{state.state:03x} {state.msg}")
    forward = base.call(VehicleMoveForward, f"{BASE}/move_forward", x=500.0).motion_id
    waited = base.run_goal(VehicleWaitMotion, f"{BASE}/wait_motion", motion_id=forward)
    print(f"forward (motion {forward}) completed: {waited.completed}, at x {round(waited.pos.x)} mm")

    paths = {base.call(VehicleMoveCruiseAbs, f"{BASE}/move_cruise_abs",
                       cruise_point=VehiclePoint(x=x, y=y)).motion_id for x, y in CRUISE}
    print(f"{len(CRUISE)} cruise points, {len(paths)} path: motion {min(paths)}")
    quarters = set()

    def pose(feedback: VehicleWaitMotion.Feedback) -> None:
        quarter = int(feedback.progress * 4)
        if quarter not in quarters:
            quarters.add(quarter)
            print(f"  {feedback.progress:4.0%} at x {round(feedback.pos.x)} y {round(feedback.pos.y)} mm")
    waited = base.run_goal(VehicleWaitMotion, f"{BASE}/wait_motion", pose, motion_id=max(paths))
    print(f"cruise completed: {waited.completed}")
    p = base.call(VehicleGetPosition, f"{BASE}/get_position").pos
    print(f"position x {round(p.x)} mm, y {round(p.y)} mm, theta {p.theta:.1f} degree")
    base.call(VehicleSetServo, f"{BASE}/set_servo", on_off=False)
    base.call(VehicleSetPower, f"{BASE}/set_power", on_off=False)
    base.close()


if __name__ == "__main__":
    main()
