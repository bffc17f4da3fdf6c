"""The operation table of the arm: one row per IDL operation of the common and middle-level ports."""
from acti_msgs import srv

from acti_bringup.adapter import Operation

OPERATIONS: tuple[Operation, ...] = (
    # common port
    Operation("servo_on", srv.ServoON),
    Operation("servo_off", srv.ServoOFF),
    Operation("get_state", srv.GetState),
    Operation("get_feedback_pos_joint", srv.GetFeedbackPosJoint),
    # middle-level motion port
    Operation("set_speed_joint", srv.SetSpeedJoint),
    Operation("move_ptp_joint_abs", srv.MovePTPJointAbs),
)
