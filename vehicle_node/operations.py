"""The operation table of the base: one row per VehicleService IDL operation (the IDL's order)."""
from acti_msgs import srv

from acti_bringup.adapter import Operation

OPERATIONS: tuple[Operation, ...] = (
    Operation("clear_alarm", srv.VehicleClearAlarm),
    Operation("get_acceleration_limit", srv.VehicleGetAccelerationLimit),
    Operation("get_active_alarm", srv.VehicleGetActiveAlarm),
    Operation("get_battery_voltage", srv.VehicleGetBatteryVoltage),
    Operation("get_default_acceleration", srv.VehicleGetDefaultAcceleration),
    Operation("get_default_velocity", srv.VehicleGetDefaultVelocity),
    Operation("get_if_version", srv.VehicleGetIFVersion),
    Operation("get_input", srv.VehicleGetInput),
    Operation("get_position", srv.VehicleGetPosition),
    Operation("get_servo_status", srv.VehicleGetServoStatus),
    Operation("get_state", srv.VehicleGetState),
    Operation("get_velocity_limit", srv.VehicleGetVelocityLimit),
    Operation("get_version", srv.VehicleGetVersion),
    Operation("move_circular_rel", srv.VehicleMoveCircularRel),
    Operation("move_forward", srv.VehicleMoveForward),
    Operation("move_jog", srv.VehicleMoveJog),
    Operation("move_linear_abs", srv.VehicleMoveLinearAbs),
    Operation("move_linear_rel", srv.VehicleMoveLinearRel),
    Operation("move_turn", srv.VehicleMoveTurn),
    Operation("pause", srv.VehiclePause),
    Operation("resume", srv.VehicleResume),
    Operation("set_acceleration", srv.VehicleSetAcceleration),
    Operation("set_digital_sensor_lock", srv.VehicleSetDigitalSensorLock),
    Operation("set_jog_timeout", srv.VehicleSetJogTimeout),
    Operation("set_joystick", srv.VehicleSetJoystick),
    Operation("set_output", srv.VehicleSetOutput),
    Operation("set_position", srv.VehicleSetPosition),
    Operation("set_power", srv.VehicleSetPower),
    Operation("set_servo", srv.VehicleSetServo),
    Operation("set_velocity", srv.VehicleSetVelocity),
    Operation("stop", srv.VehicleStop),
    Operation("unlock", srv.VehicleUnlock),
)
