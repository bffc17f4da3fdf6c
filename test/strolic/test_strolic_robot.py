"""The robot-control functions ED00–ED23 on the simulated arm, without ROS: the case table
(strolic_robot_cases.py), then what the simulation shows: poses reached, blending through via
points without stopping, $WAIT and DELAY timing, PAUSE, motion errors and cancel as exceptions
that stop the arm."""
from __future__ import annotations

import math

import numpy as np
import pytest

from acti_motion.arm import ArmConfig, ArmCore
from acti_motion.programs import ProgramRun, Status
from sim_fixtures import executor  # noqa: F401
from strolic.errors import ExceptionKind as K
from strolic_robot_cases import CASES, WORK, Check

MAX_SIM_SECONDS = 60.0


@pytest.fixture
def arm(executor):  # noqa: F811
    a = ArmCore(executor, ArmConfig(queue_size=8, initial_joints_deg=WORK))
    assert a.servo_on().ok
    return a


def run(arm, executor, text, *, servo=True, resume_after=None, hook=None, **options):  # noqa: F811
    """Run a program, stepping the simulation while it waits; `hook()` after every step."""
    if not servo:
        assert arm.servo_off().ok
    t0 = executor.world.time

    def step():
        executor.step()
        elapsed = executor.world.time - t0
        if elapsed > MAX_SIM_SECONDS:
            raise AssertionError(f"the program ran for more than {MAX_SIM_SECONDS} s")
        if resume_after is not None and elapsed >= resume_after and arm.device.paused:
            assert arm.resume().ok
        if hook is not None:
            hook()
    return ProgramRun(arm, text, step=step, **options).run()


CASE_ROWS = [pytest.param(case[0], case[1], case[2] if len(case) > 2 else {},
                          id=f"{mnemonic}-{i}")
             for mnemonic, cases in CASES.items() for i, case in enumerate(cases)]


@pytest.mark.parametrize("program, expected, options", CASE_ROWS)
def test_case(arm, executor, program, expected, options):  # noqa: F811
    result = run(arm, executor, program, **options)
    if isinstance(expected, K):
        assert result.status is Status.EXCEPTION, (result.stack, result.console)
        assert result.error.kind is expected, result.report
    else:
        assert result.status is Status.FINISHED, (result.report, result.console)
        if isinstance(expected, Check):
            assert expected(result.stack, arm), (expected.what, result.stack, result.console)
        else:
            assert result.stack == expected, result.console
