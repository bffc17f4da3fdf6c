"""The timing of a replay: the job's simulated time read from its /clock, each input's anchor,
the answers it waits for, when it is due, its measured error, and what that error allows a
device's later reads."""
from types import SimpleNamespace

import pytest

from acti_record.calls import Call
from acti_record.reading import Channel, Message
from acti_record.timing import NEVER, ClockMap, Plan, SpeedTrack

MS = 1_000_000
CMD_VEL = Channel("/cmd_vel", "geometry_msgs/msg/Twist", "", "cdr")


def test_the_clock_map_interpolates_holds_and_runs_on_at_the_jobs_rate():
    clock = ClockMap()
    for wall, sim in ((1000, 0), (1010, 10), (1060, 20), (1070, 30)):   # held up 40 ms
        clock.add(wall * MS, sim * MS)
    clock.add(1065 * MS, 25 * MS)                   # out of order: ignored
    assert clock.sim_at(1005 * MS) == pytest.approx(5 * MS)
    assert clock.sim_at(1035 * MS) == pytest.approx(15 * MS)   # within the hold-up: one period
    assert clock.sim_at(1100 * MS) == pytest.approx((30 + 30 * 30 / 70) * MS)
    assert clock.period_ns() == 10 * MS
    assert ClockMap().sim_at(123) == 123            # no /clock: the wall clock


def test_a_speed_track_gives_the_peak_around_a_span():
    track = SpeedTrack()
    for t, v in ((0, 0.0), (10, 5.0), (20, -80.0), (30, 1.0), (40, 0.0)):
        track.add(t, v)
    assert track.peak(21, 29) == 80.0               # the samples on either side count
    assert track.peak(31, 50) == 1.0
    assert SpeedTrack().peak(0, 1) == 0.0


def call(service: str, request_ms: int, response_ms: int | None) -> Call:
    return Call(service, "pkg/srv/S", None, request_ms * MS, None,
                None if response_ms is None else response_ms * MS)


def tour() -> Plan:
    """A move, a read while moving, a stop, a read after it; a jog of two messages after it."""
    calls = [call("/base/move", 0, 1), call("/base/get_state", 500, 501),
             call("/base/stop", 1000, 1001), call("/base/get_position", 2000, 2001),
             call("/arm/get_state", 2500, 2501)]
    jog = [Message(CMD_VEL, 3000 * MS, 3000 * MS, b""), Message(CMD_VEL, 0, 3100 * MS, b"")]
    clock = ClockMap()
    for t in range(0, 4000, 10):
        clock.add(t * MS + 7 * MS, t * MS)         # simulated time 7 ms behind the wall clock
    return Plan(calls, jog, lambda c: c.service.rsplit("/", 1)[0], {"/cmd_vel": "/base"}, clock)


def test_inputs_follow_their_anchor_and_wait_for_the_answers_before_them():
    plan = tour()
    assert plan.inputs == [("call", 0), ("call", 1), ("call", 2), ("call", 3), ("call", 4),
                           ("message", 0), ("message", 1)]
    assert plan.devices == ["/base"] * 4 + ["/arm"] + ["/base"] * 2
    assert plan.waits == [set(), {0}, {0, 1}, {0, 1, 2}, {0, 1, 2, 3}, {0, 1, 2, 3, 4},
                          {0, 1, 2, 3, 4}]
    # the get_state follows the move's answer, the jog's second message its first
    answers = [plan.answer_event[k] for k in range(5)]
    assert plan.anchors[0] is None and plan.anchors[1] == answers[0]
    assert plan.anchors[6] == plan.event_of[5]
    assert plan.nth_of_service == [0, 0, 0, 0, 0]


def test_an_input_is_due_at_its_recorded_offset_on_the_jobs_clock():
    plan = tour()
    job = ClockMap()
    for t in range(0, 10000, 10):
        job.add(t * MS, t * MS + 50 * MS)          # another job: its own simulated time
    assert plan.due_ns(0, {}, job, 1.0) == NEVER
    answered = {plan.answer_event[0]: 4000 * MS}
    assert plan.due_ns(1, answered, job, 1.0) == pytest.approx((4050 + 499) * MS)
    assert plan.due_ns(1, answered, job, 2.0) == pytest.approx((4050 + 249.5) * MS)


def test_a_late_stop_carries_its_drift_into_every_later_read_of_its_device():
    plan = tour()
    speeds = {"/base": SpeedTrack(), "/arm": SpeedTrack()}
    for t, v in ((0, 0.0), (400 * MS, 500.0), (1300 * MS, 0.0), (3050 * MS, 200.0),
                 (3700 * MS, 0.0)):
        speeds["/base"].add(t, v)
    job = ClockMap()
    job.add(0, 0)
    job.add(10_000 * MS, 10_000 * MS)
    # as recorded (the events' own times, 7 ms later on the wall clock) but the stop 12 ms
    # late (and all after it, at their offsets from it) and the jog's second message 3 ms early
    stop = plan.recorded_ns[plan.request_event[2]]
    walls = {e: t + 7 * MS + (12 * MS if t >= stop else 0)
             for e, t in enumerate(plan.recorded_ns)}
    walls[plan.event_of[6]] -= 3 * MS
    errors = plan.errors_s(walls, job, 1.0)
    assert errors == pytest.approx([0, 0, 0.012, 0, 0, 0, -0.003], abs=1e-9)
    allowed = plan.allowances(errors, lambda d, t0, t1: speeds[d].peak(t0, t1), 0.004)
    # the move: speeds up to 500 mm/s before the read; each base input while it moves adds
    # (|error| + margin) x speed, for good; the arm's read has nothing of the base's
    assert allowed[0] == pytest.approx(500 * 0.004)
    assert allowed[1] == pytest.approx(allowed[0] + 500 * 0.004)
    assert allowed[2] == pytest.approx(allowed[1] + 500 * 0.016)          # the late stop
    # the read after it: on time, but the base still ran on from the stop (its margin)
    assert allowed[3] == pytest.approx(allowed[2] + 500 * 0.004)
    assert allowed[4] == 0.0
    assert allowed[5] == pytest.approx(allowed[3] + 200 * 0.004)          # the jog starts
    assert allowed[6] == pytest.approx(allowed[5] + 200 * 0.007)


def ramp(track: SpeedTrack, start_ms: float, top: float, accel: float, until_ms: float,
         brake_ms: float | None = None, phase_ms: float = 0.0) -> None:
    """Samples every 20 ms (from phase_ms) of a speed that rises at `accel` per s from
    start_ms to `top`, and falls again from brake_ms."""
    t = phase_ms
    while t < until_ms:
        v = min(top, max(0.0, (t - start_ms) / 1000 * accel))
        if brake_ms is not None and t > brake_ms:
            v = max(0.0, v - (t - brake_ms) / 1000 * accel)
        track.add(t * MS, v)
        t += 20


def test_a_departure_is_where_the_speed_began_to_change_whatever_the_samples_phase():
    for phase in (0.0, 7.0, 13.0):
        track = SpeedTrack()
        ramp(track, 105.0, 300.0, 500.0, 3000.0, brake_ms=2007.0, phase_ms=phase)
        assert track.departure(50 * MS, 1000 * MS, 1.0) == pytest.approx(105 * MS, abs=0.01 * MS)
        assert track.departure(1000 * MS, 3000 * MS, 1.0) == pytest.approx(2007 * MS, abs=0.01 * MS)
        assert track.departure(1000 * MS, 1900 * MS, 1.0) is None      # steady until then


def test_the_jobs_own_reaction_time_is_timed_in_both_runs():
    plan = tour()                                   # the stop is taken at 1000 ms
    recorded, replayed = SpeedTrack(), SpeedTrack()
    ramp(recorded, 3.0, 500.0, 2000.0, 2000.0, brake_ms=1003.0)   # starts, brakes 10 ms after
    ramp(replayed, 53.0, 500.0, 2000.0, 2000.0, brake_ms=1123.0)  # 60 ms; 130 ms after
    job = ClockMap()
    job.add(0, 0)
    job.add(10_000 * MS, 10_000 * MS)
    # all on time: the job's simulated time as the recording's (7 ms behind its wall clock)
    walls = {e: t - 7 * MS for e, t in enumerate(plan.recorded_ns)}
    found = plan.reaction_errors("/base", recorded, replayed, walls, job, 1.0)
    assert [round(t / MS) for t, _ in found] == [3, 1003]
    assert [e for _, e in found] == [pytest.approx(0.050, abs=1e-5), pytest.approx(0.120, abs=1e-5)]
    speeds = {"/base": recorded}
    allowed = plan.allowances([0.0] * 7, lambda d, t0, t1: speeds[d].peak(t0, t1) if d in speeds
                              else 0.0, 0.0, {"/base": found})
    assert allowed[3] == pytest.approx(500 * 0.050 + 500 * 0.120)    # the read after the stop


def answered(id_: int) -> SimpleNamespace:
    return SimpleNamespace(return_id=SimpleNamespace(id=id_, comment=""))


def arm_plan(*calls_ms: tuple[str, int, int]) -> Plan:
    """The arm's calls (operation, request ms, return id), each answered 1 ms later; the
    simulated time is the recording's wall time."""
    calls = [Call(f"/arm/{name}", "pkg/srv/S", None, t * MS, answered(id_), (t + 1) * MS)
             for name, t, id_ in calls_ms]
    clock = ClockMap()
    for t in range(0, 5000, 10):
        clock.add(t * MS, t * MS)
    return Plan(calls, [], lambda c: c.service.rsplit("/", 1)[0], {}, clock)


def arm_moving(*spans_ms: tuple[int, int]) -> SpeedTrack:
    """30 degree/s within the spans, at rest elsewhere: samples every 20 ms to 4 s."""
    track = SpeedTrack()
    for t in range(0, 4000, 20):
        track.add(t * MS, 30.0 if any(a <= t < b for a, b in spans_ms) else 0.0)
    return track


def allowed_after(plan: Plan, track: SpeedTrack, errors: list[float]) -> list[float]:
    return plan.allowances(errors, lambda d, t0, t1: track.peak(t0, t1), 0.004,
                           arrivals={"/arm": plan.arrivals("/arm", track, 1.0)})


def test_an_arrival_at_an_absolute_place_ends_the_drift_of_its_device():
    # a move, a pause 20 ms late, resume, a move to an absolute place queued behind; it ends
    # at 2000 ms; a read while it arrives (the replay's device may be 36 ms late), one after
    plan = arm_plan(("move_ptp_joint_rel", 0, 0), ("pause", 300, 0), ("resume", 500, 0),
                    ("move_ptp_joint_abs", 600, 0), ("get_feedback_pos_joint", 2010, 0),
                    ("get_state", 2200, 0), ("get_feedback_pos_joint", 2500, 0))
    track = arm_moving((0, 300), (500, 2000))
    assert plan.commanding == [True] * 4 + [False] * 3
    assert plan.absolute == [False, False, False, True, False, False, False]
    assert plan.arrivals("/arm", track, 1.0) == [2000 * MS]
    errors = [0.0, 0.020, 0.0, 0.0, 0.0, 0.0, 0.0]
    allowed = allowed_after(plan, track, errors)
    before = allowed[3]
    assert before == pytest.approx(30 * (0.004 + 0.024 + 0.004 + 0.004))
    assert allowed[4] > before                   # within the 36 ms it may take to arrive
    # arrived in both runs: what the timing left is gone, and at rest a read's own timing
    # moves nothing
    assert allowed[5] == allowed[6] == 0.0
    # without the arrivals: the drift is carried on for good
    carried = plan.allowances(errors, lambda d, t0, t1: track.peak(t0, t1), 0.004)
    assert carried[6] > before


@pytest.mark.parametrize("calls, moving", [
    # refused: the arm is where the move before left it
    ((("move_ptp_joint_rel", 0, 0), ("move_ptp_joint_abs", 100, -3)), ((0, 1000),)),
    # a stop before it arrived: somewhere on the way
    ((("move_ptp_joint_abs", 0, 0), ("stop", 800, 0)), ((0, 1000),)),
    # a move given before the replay's device surely arrived (1000 ms + its timing errors)
    ((("move_ptp_joint_abs", 0, 0), ("move_ptp_joint_rel", 1005, 0)), ((0, 1000), (1020, 1500))),
    # a relative move queued behind it: the rest is that move's end
    ((("move_ptp_joint_abs", 0, 0), ("move_ptp_joint_rel", 100, 0)), ((0, 1000), (1020, 1500))),
])
def test_no_arrival_ends_the_drift_unless_the_device_surely_is_at_the_absolute_place(calls, moving):
    plan = arm_plan(*calls, ("get_feedback_pos_joint", 3000, 0))
    track = arm_moving(*moving)
    errors = [0.030] * len(calls) + [0.0]
    allowed = allowed_after(plan, track, errors)
    carried = plan.allowances(errors, lambda d, t0, t1: track.peak(t0, t1), 0.004)
    assert allowed == carried
