"""vehicle_node as a real process over DDS: the operation table, nested messages both ways,
refusals that leave the node up."""
import math

from acti_msgs import srv
from acti_msgs.msg import VehicleAlarm, VehiclePoint, VehiclePosition, VehicleVelocity

from ros_harness import node_fixture, wait_until
from vehicle_node.operations import OPERATIONS

vehicle = node_fixture("vehicle_node")
BASE = "/vehicle_node/"

SERVICES = {
    "clear_alarm": srv.VehicleClearAlarm, "get_acceleration_limit": srv.VehicleGetAccelerationLimit,
    "get_active_alarm": srv.VehicleGetActiveAlarm, "get_battery_voltage": srv.VehicleGetBatteryVoltage,
    "get_default_acceleration": srv.VehicleGetDefaultAcceleration,
    "get_default_velocity": srv.VehicleGetDefaultVelocity, "get_if_version": srv.VehicleGetIFVersion,
    "get_input": srv.VehicleGetInput, "get_position": srv.VehicleGetPosition,
    "get_servo_status": srv.VehicleGetServoStatus, "get_state": srv.VehicleGetState,
    "get_velocity_limit": srv.VehicleGetVelocityLimit, "get_version": srv.VehicleGetVersion,
    "move_circular_rel": srv.VehicleMoveCircularRel, "move_continuous_rel": srv.VehicleMoveContinuousRel,
    "move_cruise_abs": srv.VehicleMoveCruiseAbs, "move_forward": srv.VehicleMoveForward,
    "move_jog": srv.VehicleMoveJog, "move_linear_abs": srv.VehicleMoveLinearAbs,
    "move_linear_rel": srv.VehicleMoveLinearRel, "move_turn": srv.VehicleMoveTurn,
    "pause": srv.VehiclePause, "resume": srv.VehicleResume, "set_acceleration": srv.VehicleSetAcceleration,
    "set_digital_sensor_lock": srv.VehicleSetDigitalSensorLock, "set_jog_timeout": srv.VehicleSetJogTimeout,
    "set_joystick": srv.VehicleSetJoystick, "set_output": srv.VehicleSetOutput,
    "set_position": srv.VehicleSetPosition, "set_power": srv.VehicleSetPower, "set_servo": srv.VehicleSetServo,
    "set_velocity": srv.VehicleSetVelocity, "stop": srv.VehicleStop, "unlock": srv.VehicleUnlock,
}


def call(ros, name, **fields):
    return ros.call(SERVICES[name], BASE + name, **fields)


def state(ros):
    return call(ros, "get_state").state


def test_every_operation_of_the_table_is_a_service(ros, vehicle):
    assert len(SERVICES) == 34                                     # the IDL appendix
    served = {}
    wait_until(lambda: served.update(ros.node.get_service_names_and_types())
               or all(BASE + op.name in served for op in OPERATIONS), 10.0)
    for op in OPERATIONS:
        assert served.get(BASE + op.name) == [f"acti_msgs/srv/{SERVICES[op.name].__name__}"], op.name


def test_versions_limits_and_nested_replies(ros, vehicle):
    assert call(ros, "get_if_version").version == "RTC VehicleService interface: ver.2.0.0"
    assert call(ros, "get_version").ver.startswith("Ver.")
    r = call(ros, "get_velocity_limit")
    assert r.success and (r.vel_limit_t, r.vel_limit_r) == (1000.0, 90.0)
    d = call(ros, "get_default_velocity").default_vel
    assert (d.translation, d.rotation) == (300.0, 45.0)
    assert call(ros, "get_battery_voltage").voltage > 500.0


def test_settings_and_alarms_over_dds(ros, vehicle):
    r = call(ros, "set_velocity", vel=VehicleVelocity(translation=math.nan, rotation=10.0))
    assert not r.success and "finite" in r.message
    r = call(ros, "get_active_alarm", num_of_alarm=5)
    assert r.success and r.num_of_active_alarm >= 1
    a = r.active_alarms[-1]
    assert (a.code, a.type) == (101, VehicleAlarm.WARNING) and "set_velocity" in a.source
    assert call(ros, "clear_alarm").success
    assert call(ros, "set_velocity", vel=VehicleVelocity(translation=500.0, rotation=60.0)).success
    assert call(ros, "set_output", ioid=1, output=0b1010, mask=0b1111).success
    assert call(ros, "get_input", ioid=2).input == 0b1010
    r = call(ros, "set_output", ioid=0, output=1, mask=1)
    assert not r.success and "reserved" in r.message
    assert vehicle.alive()


def test_moves_over_dds(ros, vehicle):
    r = call(ros, "move_forward", x=500.0)
    assert not r.success and "Unpowered" in r.message
    assert call(ros, "set_power", on_off=True).success
    assert call(ros, "set_servo", on_off=True).success
    r = call(ros, "get_state")
    assert (r.state, r.msg) == (0x010, "Ready")
    assert call(ros, "set_position", pos=VehiclePosition(x=0.0, y=0.0, theta=0.0)).success
    r = call(ros, "move_circular_rel", center_point=VehiclePoint(x=0.0, y=400.0), theta=90.0)
    assert r.success and r.motion_id >= 1
    r = call(ros, "move_linear_abs", pos=VehiclePosition(x=0.0, y=800.0, theta=180.0))
    assert r.success
    assert wait_until(lambda: state(ros) == 0x010, 30.0)
    pos = call(ros, "get_position").pos
    assert math.hypot(pos.x, pos.y - 800.0) < 5.0 and abs(abs(pos.theta) - 180.0) < 0.5
    r = call(ros, "move_circular_rel", center_point=VehiclePoint(x=10.0, y=400.0), theta=90.0)
    assert not r.success and "x = 0" in r.message
    assert vehicle.alive()
