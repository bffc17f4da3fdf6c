"""The README's quick tour, then the examples of the arm's actions and of a robot program in docs/, pasted
in order into bash against the main job, work: every service call is answered with success,
every goal and program ends well, the jog and the echo run.

The `ros2` of `tools/bin` (tools/ros2_lite.py: the real CLI is not on PyPI) runs the lines; the two
commands that run until Ctrl-C get a bound (`topic pub -t 10`, `topic echo --once`)."""
import os
import re
import subprocess

from acti_bringup.harness import ROOT
from ros_harness import node_fixture

robot = node_fixture("acti_bringup")
TOUR_TIMEOUT_S = 240      # below the suite's 300 s per test: a hang shows its output


PASTED = (("README.md", "## Quick tour"), ("docs/interfaces.md", "## acti_middle_node actions and topics"),
          ("docs/programs.md", "## Robot programs"))


def first_bash_block(path: str, heading: str) -> str:
    with open(os.path.join(ROOT, path), encoding="utf-8") as f:
        text = f.read()
    return text.split(f"\n{heading}\n", 1)[1].split("```bash\n", 1)[1].split("```", 1)[0]


def quick_tour() -> str:
    """The first bash block under each heading of PASTED, the endless commands bounded."""
    block = "".join(first_bash_block(path, heading) for path, heading in PASTED)
    block = re.sub(r"^ros2 topic pub ", "ros2 topic pub -t 10 ", block, flags=re.M)
    return re.sub(r"^ros2 topic echo ", "ros2 topic echo --once ", block, flags=re.M)


def test_the_quick_tour_works_pasted_in_order(robot):
    tour = quick_tour()
    env = dict(os.environ, PATH=os.path.join(ROOT, "tools", "bin") + os.pathsep
               + os.environ["PATH"])
    done = subprocess.run(["bash", "-e", "-c", tour], env=env, cwd=ROOT, capture_output=True,
                          text=True, timeout=TOUR_TIMEOUT_S)
    out = done.stdout + done.stderr
    assert done.returncode == 0, out
    responses = re.findall(r"^response:\n(.*)$", out, flags=re.M)
    requests = out.count("requester: making request")
    assert requests >= tour.count("ros2 service call") and len(responses) == requests, out
    refused = [r for r in responses if "success=False" in r or "ReturnId(id=-" in r]
    assert not refused, "\n".join(refused)
    finished = re.findall(r"Goal finished with status: (\w+)", out)
    assert finished and set(finished) == {"SUCCEEDED"}, out
    assert "completed: true" in out and "completed: false" not in out, out
    assert out.count("publishing #") == 10, out
    assert re.search(r"^msg: \w+", out, flags=re.M), out      # the echoed ~/state
