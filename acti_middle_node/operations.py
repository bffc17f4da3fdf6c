"""The operation table of the arm: one row per IDL operation of the common and middle-level ports
(in the spec's order), then the 2014 revision's extensions."""
from acti_msgs import srv

from acti_bringup.serving.adapter import Operation

COMMON_PORT: tuple[Operation, ...] = (
    Operation("clear_alarms", srv.ClearAlarms),
    Operation("get_active_alarm", srv.GetActiveAlarm),
    Operation("get_feedback_pos_joint", srv.GetFeedbackPosJoint),
    Operation("get_manip_info", srv.GetManipInfo),
    Operation("get_soft_limit_joint", srv.GetSoftLimitJoint),
    Operation("get_state", srv.GetState),
    Operation("servo_off", srv.ServoOFF),
    Operation("servo_on", srv.ServoON),
    Operation("set_soft_limit_joint", srv.SetSoftLimitJoint),
)

MIDDLE_PORT: tuple[Operation, ...] = (
    Operation("close_gripper", srv.CloseGripper),
    Operation("get_base_offset", srv.GetBaseOffset),
    Operation("get_feedback_pos_cartesian", srv.GetFeedbackPosCartesian),
    Operation("get_max_speed_cartesian", srv.GetMaxSpeedCartesian),
    Operation("get_max_speed_joint", srv.GetMaxSpeedJoint),
    Operation("get_min_accel_time_cartesian", srv.GetMinAccelTimeCartesian),
    Operation("get_min_accel_time_joint", srv.GetMinAccelTimeJoint),
    Operation("get_soft_limit_cartesian", srv.GetSoftLimitCartesian),
    Operation("move_gripper", srv.MoveGripper),
    Operation("move_linear_cartesian_abs", srv.MoveLinearCartesianAbs),
    Operation("move_linear_cartesian_rel", srv.MoveLinearCartesianRel),
    Operation("move_ptp_cartesian_abs", srv.MovePTPCartesianAbs),
    Operation("move_ptp_cartesian_rel", srv.MovePTPCartesianRel),
    Operation("move_ptp_joint_abs", srv.MovePTPJointAbs),
    Operation("move_ptp_joint_rel", srv.MovePTPJointRel),
    Operation("open_gripper", srv.OpenGripper),
    Operation("pause", srv.Pause),
    Operation("resume", srv.Resume),
    Operation("stop", srv.Stop),
    Operation("set_accel_time_cartesian", srv.SetAccelTimeCartesian),
    Operation("set_accel_time_joint", srv.SetAccelTimeJoint),
    Operation("set_base_offset", srv.SetBaseOffset),
    Operation("set_control_point_offset", srv.SetControlPointOffset),
    Operation("set_max_speed_cartesian", srv.SetMaxSpeedCartesian),
    Operation("set_max_speed_joint", srv.SetMaxSpeedJoint),
    Operation("set_min_accel_time_cartesian", srv.SetMinAccelTimeCartesian),
    Operation("set_min_accel_time_joint", srv.SetMinAccelTimeJoint),
    Operation("set_soft_limit_cartesian", srv.SetSoftLimitCartesian),
    Operation("set_speed_cartesian", srv.SetSpeedCartesian),
    Operation("set_speed_joint", srv.SetSpeedJoint),
)

# The 2014 (SI-unit) revision's additions, offered in the same style and units.
EXTENSIONS: tuple[Operation, ...] = (
    Operation("move_circular_cartesian_abs", srv.MoveCircularCartesianAbs),
    Operation("move_circular_cartesian_rel", srv.MoveCircularCartesianRel),
    Operation("set_home", srv.SetHome),
    Operation("get_home", srv.GetHome),
    Operation("go_home", srv.GoHome),
)

OPERATIONS: tuple[Operation, ...] = COMMON_PORT + MIDDLE_PORT + EXTENSIONS
