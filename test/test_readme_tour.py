"""The README's quick tour pasted into one bash, in order, on a robot just started at real time (as
`make run` starts it): every command works and prints what its comment promises. Then the examples
of the arm's actions (docs/interfaces.md) and of a robot program (docs/programs.md) pasted the
same way: every call answered OK, every goal and program ends well.

A tour comment is `# PROMISES — prose`: each promise is `name=value` (every response the command
prints has that field with that value), `name: value` (every such line of what it prints has
that value) or `name<value`; a number ending in … is the printed one rounded to the digits shown.
Prose is not checked, but for the phrases of PROSE_CHECKS. A comment this test cannot check
fails it. The `ros2` of `tools/bin` (tools/ros2_lite.py: the real CLI is not on PyPI) runs the
lines; the jog, which runs until Ctrl-C, gets a bound (`topic pub -t 10`)."""
from __future__ import annotations

import math
import os
import re
import subprocess
from dataclasses import dataclass

from acti_bringup.harness import ROOT
from ros_harness import node_fixture

robot = node_fixture("acti_bringup", "real_time_factor:=1.0")   # the tour's timing is the user's
TOUR_TIMEOUT_S = 280      # below the suite's 300 s per test: a hang shows its output
MARK = "=== tour command "
PROMISE = re.compile(r"(\w+)(=|: |<)(\[[^\]]*\]|'[^']*'|[^\s,]+)")
TRAILING_COMMENT = re.compile(r"\s{2,}# (.*)$")
WHERE_IT_IS = "ros2 service call /vehicle_node/get_position acti_msgs/srv/VehicleGetPosition"


@dataclass
class Command:
    text: str
    comment: str = ""

    def promises(self) -> list[tuple[str, str, str]]:
        """The comment's promises; a part before the dash that is not all promises fails."""
        part = self.comment.split("—", 1)[0]
        leftover = re.sub(r"[,\s]", "", PROMISE.sub("", part))
        assert not leftover, f"the tour comment '{self.comment}' is not `promises — prose`"
        return PROMISE.findall(part)

    def prose(self) -> str:
        return self.comment.split("—", 1)[1].strip() if "—" in self.comment else ""


def first_bash_block(path: str, heading: str) -> str:
    with open(os.path.join(ROOT, path), encoding="utf-8") as f:
        text = f.read()
    return text.split(f"\n{heading}\n", 1)[1].split("```bash\n", 1)[1].split("```", 1)[0]


def bounded(script: str, listeners: int | None = None) -> str:
    """The command that runs until Ctrl-C, made to end by itself; with `listeners`, its first
    message sent once that many subscriptions match (one matched later misses the first)."""
    wait = f"-w {listeners} " if listeners else ""
    return re.sub(r"^ros2 topic pub ", f"ros2 topic pub -t 10 {wait}", script, flags=re.M)


def commands(block: str) -> list[Command]:
    """The block's commands (continued lines and `for … done` as one), each with its comment:
    the one at its end, or a comment line right below it. Other comment lines are headings."""
    found: list[Command] = []
    lines = block.splitlines()
    i, after_command = 0, False
    while i < len(lines):
        line = lines[i]
        if not line.strip() or line.startswith("#"):
            if line.startswith("# ") and after_command:
                found[-1].comment = line[2:]
            after_command = False
            i += 1
            continue
        text = [line]
        while text[-1].endswith("\\") or text[0].startswith("for ") and text[-1].strip() != "done":
            i += 1
            text.append(lines[i])
        comments = [m.group(1) for m in map(TRAILING_COMMENT.search, text) if m]
        found.append(Command("\n".join(text), " ".join(comments)))
        after_command = True
        i += 1
    return found


def pasted_tour() -> list[Command]:
    """The quick tour's commands, then a read of where the jog took the base (for its check)."""
    tour = commands(first_bash_block("README.md", "## Quick tour"))
    assert tour[0].text == "source tools/env.sh", tour[0]
    return tour + [Command(WHERE_IT_IS)]


def run_pasted(script: str) -> str:
    env = dict(os.environ, PATH=os.path.join(ROOT, "tools", "bin") + os.pathsep + os.environ["PATH"])
    done = subprocess.run(["bash", "-e", "-c", script], env=env, cwd=ROOT, stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, text=True, timeout=TOUR_TIMEOUT_S)
    assert done.returncode == 0, done.stdout
    return done.stdout


def printed_as(shown: str, printed: str) -> bool:
    """`printed` is what `shown` promises: the same text, or rounded to the digits before …"""
    if shown.startswith("["):
        shown_items, printed_items = shown[1:-1].split(", "), printed[1:-1].split(", ")
        return len(shown_items) == len(printed_items) and all(
            printed_as(s, p) for s, p in zip(shown_items, printed_items))
    if shown.endswith("…"):
        digits = shown[:-1]
        decimals = len(digits.split(".")[1]) if "." in digits else 0
        return math.isclose(round(float(printed), decimals), float(digits), abs_tol=1e-9)
    return printed.strip("'") == shown.strip("'")


def responses(out: str) -> list[str]:
    return re.findall(r"^response:\n(.*)$", out, flags=re.M)


def field_values(line: str, name: str) -> list[str]:
    return re.findall(rf"\b{name}=(\[[^\]]*\]|'[^']*'|[^,)]+)", line)


def check_promise(out: str, name: str, op: str, shown: str) -> None:
    if op == ": ":
        printed = re.findall(rf"^\s*{name}: (.*)$", out, flags=re.M)
    else:
        answers = responses(out)
        assert answers, f"no response to check {name}{op}{shown} in:\n{out}"
        printed = [v for line in answers for v in field_values(line, name)]
        assert len(printed) == len(answers), f"{name} is not in every response:\n{out}"
    assert printed, f"{name} is not printed:\n{out}"
    for value in printed:
        ok = float(value) < float(shown) if op == "<" else printed_as(shown, value)
        assert ok, f"promised {name}{op}{shown}, printed {name}={value}:\n{out}"


def moved_by_hand(outputs: list[str]) -> None:
    """The jog drove the base away from where the cruise ended (the last wait's result)."""
    cruise_end = [out for out in outputs if re.search(r"^\s*x: ", out, flags=re.M)][-1]
    ended = {k: float(v) for k, v in re.findall(r"^\s*([xy]): (\S+)$", cruise_end, flags=re.M)}
    now = {k: float(field_values(responses(outputs[-1])[0], k)[0]) for k in "xy"}
    assert math.hypot(now["x"] - ended["x"], now["y"] - ended["y"]) > 10.0, (ended, now)


PROSE_CHECKS = {"drives the base while it publishes": moved_by_hand}


def test_the_quick_tour_prints_what_its_comments_say(robot):
    tour = pasted_tour()
    script = "\n".join(f"echo '{MARK}{n}'\n{bounded(c.text, listeners=1)}"
                       for n, c in enumerate(tour))
    outputs = re.split(rf"^{MARK}\d+\n", run_pasted(script), flags=re.M)[1:]
    assert len(outputs) == len(tour)
    checked = 0
    for command, out in zip(tour, outputs):
        assert len(responses(out)) == out.count("requester: making request"), out
        for promise in command.promises():
            check_promise(out, *promise)
            checked += 1
        prose_checks = [check for phrase, check in PROSE_CHECKS.items() if phrase in command.prose()]
        for check in prose_checks:
            check(outputs)
        assert command.promises() or prose_checks or not command.comment, \
            f"nothing to check in the comment of {command.text!r}: {command.comment!r}"
    assert checked >= 25, checked


def test_the_examples_in_docs_work_pasted(robot):
    script = bounded(first_bash_block("docs/interfaces.md", "## acti_middle_node actions and topics")
                     + first_bash_block("docs/programs.md", "## Robot programs"))
    out = run_pasted(script)
    answers = responses(out)
    assert len(answers) == script.count("ros2 service call"), out
    refused = [r for r in answers if "success=False" in r or "ReturnId(id=-" in r]
    assert not refused, "\n".join(refused)
    finished = re.findall(r"Goal finished with status: (\w+)", out)
    assert finished and set(finished) == {"SUCCEEDED"}, out
    assert "completed: true" in out and "completed: false" not in out, out
    assert "finished" in out, out          # the program's run (run_program's CLI)
