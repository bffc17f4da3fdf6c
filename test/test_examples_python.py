"""The Python clients of examples/python/, run as a user runs them beside `make run`: each ends
well over DDS and prints what its docstring says it does."""
import os
import re
import subprocess
import sys

from acti_bringup.harness import ROOT
from ros_harness import node_fixture

robot = node_fixture("acti_bringup")
EXAMPLES = os.path.join(ROOT, "examples", "python")
RUN_TIMEOUT_S = 240


def run_example(name: str) -> str:
    done = subprocess.run([sys.executable, os.path.join(EXAMPLES, name)], cwd=ROOT,
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                          timeout=RUN_TIMEOUT_S)
    assert done.returncode == 0, done.stdout
    return done.stdout


def test_the_arm_example_moves_waits_and_reads_back(robot):
    out = run_example("arm.py")
    assert re.search(r"^queued motions (\d+) and \d+; state 0x03 ", out, flags=re.M), out
    assert re.search(r"^motion \d+ completed: True$", out, flags=re.M), out
    assert "joints [degree]: -30.0 45.0 0.0 -75.0 -20.0 60.0 0.0, gripper [mm]: 0.0" in out, out
    assert "back at the start posture: completed True, joints [degree]: " \
           "0.0 30.0 0.0 -60.0 0.0 60.0 0.0" in out, out


def test_the_base_example_drives_one_path(robot):
    out = run_example("base.py")
    assert "state 0x010 Ready" in out, out
    assert re.search(r"^forward \(motion \d+\) completed: True, at x 500 mm$", out, flags=re.M), out
    assert re.search(r"^3 cruise points, 1 path: motion \d+$", out, flags=re.M), out
    assert "cruise completed: True" in out, out
    assert re.search(r"^position x 2000 mm, y 0 mm, theta ", out, flags=re.M), out


def test_the_program_example_runs_to_its_end(robot):
    out = run_example("program.py")
    assert re.search(r"^program finished after \d+ instructions", out, flags=re.M), out
    assert "final stack: I2:0" in out, out


REFUSED_MOVE = """
from acti_client import Client
from acti_msgs.srv import MovePTPJointAbs, ServoOFF
arm = Client("refusal_example")
arm.call(ServoOFF, "/acti_middle_node/servo_off")
arm.call(MovePTPJointAbs, "/acti_middle_node/move_ptp_joint_abs", joint_points=[0.0] * 7)
"""


def test_a_refusal_ends_a_client_with_the_nodes_reason(robot):
    done = subprocess.run([sys.executable, "-c", REFUSED_MOVE], cwd=EXAMPLES, stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, text=True, timeout=RUN_TIMEOUT_S)
    assert done.returncode == 1, done.stdout
    assert done.stdout.strip().splitlines()[-1] == ("/acti_middle_node/move_ptp_joint_abs refused: "
                                                    "return id -4: servo is off: call servo_on first"), done.stdout
