"""A STROLIC robot program from Python: the program's text sent to the arm's `~/run_program`
action, its progress as it runs, then its result: status, output and final data stack.

Run it beside `make run`, in a shell that sourced tools/env.sh: python examples/python/program.py"""
from acti_client import Client

from acti_msgs.action import RunProgram
from acti_msgs.srv import ServoON

ARM = "/acti_middle_node"
STATUS = {RunProgram.Result.FINISHED: "finished", RunProgram.Result.EXCEPTION: "exception",
          RunProgram.Result.CANCELED: "canceled", RunProgram.Result.INVALID: "not loaded"}

# 50 mm down in a straight line, close the gripper, back up; the last $WAIT's error flag (0: the
# motions ran) stays on the stack
PROGRAM = """
50 JSPEED DROP  200 SPEED DROP
HERE Vec(0 0 -50) DEV ALMOVE DROP  -1 $WAIT DROP
HANDCLOSE  -1 $WAIT DROP
HERE Vec(0 0 50) DEV ALMOVE DROP   -1 $WAIT
"""


def main() -> None:
    arm = Client("program_example")
    arm.call(ServoON, f"{ARM}/servo_on")          # a program needs the servo on
    states = []

    def progress(feedback: RunProgram.Feedback) -> None:
        if not states or states[-1] != feedback.state:
            states.append(feedback.state)
            print(f"  {feedback.state} at @{feedback.program_counter}")
    result = arm.run_goal(RunProgram, f"{ARM}/run_program", progress, text=PROGRAM)
    print(f"program {STATUS[result.status]} after {result.instructions} instructions,",
          f"{result.duration:.1f} s simulated")
    print("final stack:", *result.stack)
    if result.exception:
        print(result.exception)
    arm.close()
    raise SystemExit(0 if result.status == RunProgram.Result.FINISHED else 1)


if __name__ == "__main__":
    main()
