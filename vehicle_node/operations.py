"""The operation table of the base: one row per VehicleService IDL operation."""
from acti_msgs import srv

from acti_bringup.adapter import Operation

OPERATIONS: tuple[Operation, ...] = (
    Operation("set_power", srv.VehicleSetPower),
    Operation("set_servo", srv.VehicleSetServo),
    Operation("get_state", srv.VehicleGetState),
    Operation("get_position", srv.VehicleGetPosition),
    Operation("move_forward", srv.VehicleMoveForward),
)
