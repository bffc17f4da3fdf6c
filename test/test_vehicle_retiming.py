"""The base's re-timer (acti_motion.vehicle.retiming): set_velocity's re-plan after the answer,
requests that come while it plans served by one more re-plan, and here without a thread."""
import threading

from acti_motion.vehicle.retiming import Retimer
from sim_fixtures import executor, run_until  # noqa: F401
from vehicle_fixtures import base, ready  # noqa: F401


def test_without_its_thread_the_retime_runs_before_the_request_returns():
    runs = []
    retimer = Retimer(lambda: runs.append(1))
    retimer.request()
    assert runs == [1]


def test_a_request_returns_while_its_retime_runs_and_later_ones_share_one_more():
    began, release, runs = threading.Event(), threading.Event(), []

    def retime() -> None:
        runs.append(1)
        began.set()
        assert release.wait(10.0)
    retimer = Retimer(retime)
    retimer.start()
    retimer.request()                        # returns at once, its re-plan held
    assert began.wait(10.0)
    for _ in range(5):                       # given while it plans
        retimer.request()
    assert not retimer.wait_done(0.0)
    release.set()
    assert retimer.wait_done(10.0)
    assert len(runs) == 2                    # the first, and one for the five


def test_a_failing_retime_leaves_the_thread_serving(caplog):
    runs = []

    def retime() -> None:
        runs.append(1)
        if len(runs) == 1:
            raise RuntimeError("outran")
    retimer = Retimer(retime)
    retimer.start()
    retimer.request()
    assert retimer.wait_done(10.0)
    retimer.request()
    assert retimer.wait_done(10.0)
    assert len(runs) == 2 and "keep their old timing" in caplog.text


def test_set_velocity_answers_before_a_plan_under_way_lets_its_retime_run(base, executor):  # noqa: F811
    """The planning lock held elsewhere (a plan under way): set_velocity still answers, and the
    running move takes the new speed once the lock is free."""
    ready(base)
    base.retimer.start()
    assert base.set_velocity((200.0, 45.0)).ok
    assert base.retimer.wait_done(10.0)
    assert base.move_forward(2000.0).ok
    run_until(executor, lambda: base.odometry.v > 0.15, 10.0)
    with base.planning:
        assert base.set_velocity((600.0, 45.0)).ok
        assert base.velocity == (600.0, 45.0)
    assert base.retimer.wait_done(10.0)
    run_until(executor, lambda: base.odometry.v > 0.5, 10.0)
