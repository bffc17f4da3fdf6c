"""The base's re-plans over DDS: does the simulation keep its clock while `set_velocity` re-plans
a running cruise, and how long does that answer take?

The main job (`python -m acti_bringup`, real time, /clock on every step, its control loop under
SCHED_FIFO unless `--fifo 0`) runs; a client on a thread of its own records the DDS source
timestamp of every /clock message (the job's own silences, not this client's), and those of a
bare process that only publishes a Clock every 4 ms (`clock_floor.py`: what the machine allowed
then). Four kinds of window, interleaved (A B C D A B C D …) so that the machine's drift cancels
out of the ratios:

- idle: the base at rest, no calls (the baseline of the gaps);
- at rest: the base at rest, `set_velocity` called every 20 ms (nothing to re-plan: the
  answer's own cost, the baseline of the answers);
- cruise: the base cruising a closed loop of 8 points, no calls;
- re-plans: the same cruise, `set_velocity` called every 20 ms (400 and 600 mm/s in turn),
  each a TOPP-RA re-plan of the rest of the cruise.

Per kind: the largest gap between two /clock messages, the median of each window's largest
and the p99 gap, against idle's, and the
`set_velocity` answer p50/p99 against the answers at rest. Then a long session: minutes of mixed base moves (lines,
turns, arcs, cruises, continuous moves, speed changes while moving), its largest and p99 /clock
gap against idle windows of the same run.

    python bench/bench_replan.py [--rounds N] [--window S] [--long MINUTES] [--fifo P]
"""
from __future__ import annotations

import argparse
import math
import time
from typing import Callable

import numpy as np
from common import RosClient, running

from acti_msgs import srv
from acti_msgs.msg import VehiclePoint, VehiclePosition, VehicleVelocity

from bench.bench_control_plane import Background
from bench.clock_floor import FIFO_PRIORITY

BASE = "/vehicle_node/"
READY = 0x010
CRUISE_SPEED = (600.0, 60.0)
LOOP_RADIUS = 800.0            # mm: the cruise's loop, beside the base, back to where it began


class Windows:
    """Per kind of window: the /clock gaps (s) and the set_velocity answers (s) in it."""

    def __init__(self, bg: Background) -> None:
        self.bg = bg
        self.gaps: dict[str, list[np.ndarray]] = {}
        self.answers: dict[str, list[float]] = {}
        self.bare: dict[str, list[float]] = {}       # the bare publisher's largest silence per window

    def record(self, kind: str, since: float, until: float, answers: list[float]) -> None:
        n = len(self.bg.clock_sent)
        arrived = np.array(self.bg.clock_arrivals[:n])
        sent = np.array(self.bg.clock_sent[:n])[(arrived >= since) & (arrived <= until)]
        self.gaps.setdefault(kind, []).append(np.diff(sent))
        bare = np.array(self.bg.bare_clock_sent[:len(self.bg.bare_clock_sent)])
        bare = bare[(bare >= sent[0]) & (bare <= sent[-1])]
        self.bare.setdefault(kind, []).append(float(np.max(np.diff(bare))) if len(bare) > 1 else math.inf)
        self.answers.setdefault(kind, []).extend(answers)

    def gap(self, kind: str) -> np.ndarray:
        return np.concatenate(self.gaps[kind])

    def typical_largest(self, kind: str) -> float:
        """The median over the windows of a kind of each window's largest gap: one stall of the
        machine moves the largest of all, not this."""
        return float(np.median([g.max() for g in self.gaps[kind]]))


def state(ros: RosClient) -> int:
    return ros.call(srv.VehicleGetState, BASE + "get_state").state


def position(ros: RosClient) -> VehiclePosition:
    return ros.call(srv.VehicleGetPosition, BASE + "get_position").pos


def ready(ros: RosClient) -> None:
    """Powered, servo on, Ready, at rest."""
    ros.call(srv.VehicleStop, BASE + "stop")
    ros.call(srv.VehicleSetPower, BASE + "set_power", on_off=True)
    ros.call(srv.VehicleSetServo, BASE + "set_servo", on_off=True)
    if not ros.spin_until(lambda: state(ros) == READY, 30.0):
        ros.call(srv.VehicleClearAlarm, BASE + "clear_alarm")
        assert ros.spin_until(lambda: state(ros) == READY, 30.0), hex(state(ros))


def set_velocity(ros: RosClient, translation: float, rotation: float) -> float:
    """The answer's wall time (s); the call must succeed."""
    t0 = time.perf_counter()
    r = ros.call(srv.VehicleSetVelocity, BASE + "set_velocity",
                 vel=VehicleVelocity(translation=translation, rotation=rotation))
    wall = time.perf_counter() - t0
    assert r.success, r.message
    return wall


def cruise_loop(ros: RosClient) -> None:
    """8 cruise points on a circle beside the base, the last where it began; returns once it
    cruises (300 mm from where it began)."""
    set_velocity(ros, *CRUISE_SPEED)
    here = position(ros)
    c, s = math.cos(math.radians(here.theta)), math.sin(math.radians(here.theta))
    cx, cy = here.x - LOOP_RADIUS * s, here.y + LOOP_RADIUS * c          # centre to the left
    for k in range(1, 9):
        a = -math.pi / 2 + math.radians(here.theta) + k * math.pi / 4
        point = VehiclePoint(x=cx + LOOP_RADIUS * math.cos(a), y=cy + LOOP_RADIUS * math.sin(a))
        r = ros.call(srv.VehicleMoveCruiseAbs, BASE + "move_cruise_abs", cruise_point=point)
        assert r.success, r.message
    assert ros.spin_until(lambda: math.dist((position(ros).x, position(ros).y), (here.x, here.y))
                          > 300.0, 30.0), "the cruise did not start"


KINDS = ("idle", "at rest", "cruise", "re-plans")
PACE_S = 0.02           # between an answer and the next set_velocity


def window(ros: RosClient, windows: Windows, kind: str, seconds: float) -> None:
    """One window of `kind`; the base Ready again after it."""
    moving = kind in ("cruise", "re-plans")
    if moving:
        cruise_loop(ros)
    answers: list[float] = []
    since = time.monotonic()
    end, k = since + seconds, 0
    while time.monotonic() < end:
        if kind in ("idle", "cruise"):
            ros.spin_until(lambda: False, min(0.05, end - time.monotonic()))
            continue
        answers.append(set_velocity(ros, 400.0 if k % 2 else 600.0, CRUISE_SPEED[1]))
        k += 1
        ros.spin_until(lambda: False, PACE_S)
    if moving:
        assert state(ros) != READY, "the cruise ended inside the window: make it longer"
    windows.record(kind, since, time.monotonic(), answers)
    if moving:
        ros.call(srv.VehicleStop, BASE + "stop")
    assert ros.spin_until(lambda: state(ros) == READY, 30.0), hex(state(ros))


def ms(values: np.ndarray | list[float], q: float) -> float:
    return 1e3 * float(np.percentile(values, q))


def report(windows: Windows, rounds: int, seconds: float, period: float) -> None:
    print(f"/clock gaps (DDS source timestamps; /clock every {period * 1e3:.1f} ms; bare: the bare "
          f"publisher's largest silence in the same windows) and set_velocity "
          f"answers, {rounds} interleaved rounds of {seconds:g} s per kind; times in ms")
    idle_gap, idle_answer = windows.gap("idle"), windows.answers["at rest"]
    for kind in KINDS:
        gap = windows.gap(kind)
        typical, idle_typical = windows.typical_largest(kind), windows.typical_largest("idle")
        text = (f"  {kind:9s} largest gap {gap.max() * 1e3:6.1f} (x{gap.max() / idle_gap.max():4.2f};"
                f" bare {max(windows.bare[kind]) * 1e3:5.1f}), a window's largest p50 "
                f"{typical * 1e3:5.1f} (x{typical / idle_typical:4.2f})"
                f"  p99 gap {ms(gap, 99):5.1f} (x{ms(gap, 99) / ms(idle_gap, 99):4.2f})")
        answers = windows.answers[kind]
        if answers:
            text += (f"   set_velocity answer p50 {ms(answers, 50):6.2f} "
                     f"(x{ms(answers, 50) / ms(idle_answer, 50):5.2f})  p99 {ms(answers, 99):6.2f} "
                     f"(x{ms(answers, 99) / ms(idle_answer, 99):5.2f}), {len(answers)} calls")
        print(text)


MIXED: list[tuple[str, Callable[[RosClient], object]]] = [
    ("move_forward 400", lambda ros: ros.call(srv.VehicleMoveForward, BASE + "move_forward", x=400.0)),
    ("move_turn 90", lambda ros: ros.call(srv.VehicleMoveTurn, BASE + "move_turn", theta=90.0)),
    ("move_circular_rel r 300, 90", lambda ros: ros.call(
        srv.VehicleMoveCircularRel, BASE + "move_circular_rel",
        center_point=VehiclePoint(x=0.0, y=300.0), theta=90.0)),
    ("move_linear_rel 300, 200", lambda ros: ros.call(
        srv.VehicleMoveLinearRel, BASE + "move_linear_rel",
        pos=VehiclePosition(x=300.0, y=200.0, theta=-45.0))),
    ("move_continuous_rel 500", lambda ros: ros.call(
        srv.VehicleMoveContinuousRel, BASE + "move_continuous_rel",
        pos=VehiclePosition(x=500.0, y=-200.0, theta=0.0))),
]


def long_session(ros: RosClient, windows: Windows, minutes: float) -> None:
    """Mixed base moves for `minutes`: each Ready-only move, or a cruise loop re-planned by
    set_velocity now and then, until Ready; the gaps pooled as kind "long"."""
    since, end, k = time.monotonic(), time.monotonic() + 60.0 * minutes, 0
    moves = 0
    while time.monotonic() < end:
        if k % (len(MIXED) + 1) == len(MIXED):
            cruise_loop(ros)
            for i in range(4):
                set_velocity(ros, 400.0 if i % 2 else 600.0, CRUISE_SPEED[1])
        else:
            set_velocity(ros, 300.0 + 100.0 * (k % 3), 45.0)
            r = MIXED[k % len(MIXED)][1](ros)
            assert r.success, r.message
        moves += 1
        k += 1
        assert ros.spin_until(lambda: state(ros) == READY, 60.0), hex(state(ros))
    windows.record("long", since, time.monotonic(), [])
    gap, idle = windows.gap("long"), windows.gap("idle")
    print(f"long session: {minutes:g} min of mixed base moves ({moves} moves: lines, turns, arcs, "
          f"continuous moves, cruise loops re-planned by set_velocity)")
    print(f"  largest gap {gap.max() * 1e3:6.1f} ms (x{gap.max() / idle.max():4.2f} idle's "
          f"{idle.max() * 1e3:.1f})  p99 gap {ms(gap, 99):5.1f} ms (x{ms(gap, 99) / ms(idle, 99):4.2f})")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--rounds", type=int, default=8)
    parser.add_argument("--window", type=float, default=4.0, help="seconds per window")
    parser.add_argument("--long", type=float, default=3.0, help="minutes of the long session (0: none)")
    parser.add_argument("--fifo", type=int, default=FIFO_PRIORITY,
                        help="the job's control_fifo_priority (0: the default, no real-time class)")
    args = parser.parse_args()
    ros = RosClient(call_timeout=30.0)
    print(f"main job: control_fifo_priority {args.fifo}, /clock on every step (250 Hz); beside it "
          f"a bare process publishing a Clock every 4 ms (SCHED_FIFO {FIFO_PRIORITY}: what the "
          "machine allowed)")
    with running("bench.clock_floor"), \
            running("acti_bringup", "clock_rate_hz:=250.0", f"control_fifo_priority:={args.fifo}"):
        bg = Background()
        try:
            ready(ros)
            assert ros.spin_until(lambda: len(bg.clock_values) > 100, 60.0), "no /clock"
            period = bg.control_period()
            windows = Windows(bg)
            for kind in KINDS:          # warm-up, not recorded
                window(ros, Windows(bg), kind, 1.0)
            for _ in range(args.rounds):
                for kind in KINDS:
                    window(ros, windows, kind, args.window)
            report(windows, args.rounds, args.window, period)
            if args.long > 0:
                long_session(ros, windows, args.long)
        finally:
            bg.close()
    ros.close()


if __name__ == "__main__":
    main()
