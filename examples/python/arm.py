"""The arm from Python: servo on, two moves queued by the services (each answers at once with its
motion id), a wait for them with progress, where the arm is then, one more move by the `~/move`
action (it answers when the move is over), servo off.

Run it beside `make run`, in a shell that sourced tools/env.sh: python examples/python/arm.py"""
from acti_client import Client

from acti_msgs.action import Move, WaitMotion
from acti_msgs.srv import (GetFeedbackPosJoint, GetState, MovePTPJointAbs, ServoOFF, ServoON,
                           SetSpeedJoint)

ARM = "/acti_middle_node"
START = [0.0, 30.0, 0.0, -60.0, 0.0, 60.0, 0.0]        # the start posture [degree]


def tenths(values) -> str:
    return " ".join(f"{round(v, 1) + 0.0:.1f}" for v in values)      # + 0.0: no "-0.0"


def main() -> None:
    arm = Client("arm_example")
    arm.call(ServoON, f"{ARM}/servo_on")
    arm.call(SetSpeedJoint, f"{ARM}/set_speed_joint", spd_ratio=50)    # 0 % at start-up
    first = arm.call(MovePTPJointAbs, f"{ARM}/move_ptp_joint_abs",
                     joint_points=[30.0, 45.0, 0.0, -75.0, 20.0, 60.0, 0.0]).motion_id
    second = arm.call(MovePTPJointAbs, f"{ARM}/move_ptp_joint_abs",
                      joint_points=[-30.0, 45.0, 0.0, -75.0, -20.0, 60.0, 0.0]).motion_id
    state = arm.call(GetState, f"{ARM}/get_state").state
    print(f"queued motions {first} and {second}; state 0x{state:02x} (0x01 servo on, 0x02 moving)")

    seen = set()

    def progress(feedback: WaitMotion.Feedback) -> None:
        if feedback.current_motion_id not in seen:
            seen.add(feedback.current_motion_id)
            print(f"  running motion {feedback.current_motion_id} ({feedback.current_label})")
    waited = arm.run_goal(WaitMotion, f"{ARM}/wait_motion", progress, motion_id=second)
    print(f"motion {waited.motion_id} completed: {waited.completed}")
    joints = arm.call(GetFeedbackPosJoint, f"{ARM}/get_feedback_pos_joint").pos
    print(f"joints [degree]: {tenths(joints[:7])}, gripper [mm]: {tenths(joints[7:])}")

    moved = arm.run_goal(Move, f"{ARM}/move", kind=Move.Goal.PTP_JOINT_ABS, joint_points=START)
    print(f"back at the start posture: completed {moved.completed},",
          f"joints [degree]: {tenths(moved.joint_pos[:7])}")
    arm.call(ServoOFF, f"{ARM}/servo_off")
    arm.close()


if __name__ == "__main__":
    main()
