"""The timing of a replay, and what it allows a measured answer.

A replay cannot send a request at the very moment of the job's simulated time it came in the
recording: a read taken while a device moves, or a stop given to a moving base, lands a few
milliseconds earlier or later, and the device is that much further on. Every input of a replay
(a call, a republished command message) is timed on the job's own clock, its simulated time
(`ClockMap`), at its recorded offset from the event it followed (a request taken, an answer sent,
a message published); what it missed by is measured on the same clock in both runs
(`Plan.errors_s`). While the recording shows its device moving, that error moves the device
by up to its speed times the error, and the difference stays in every later read of the device
(a stop given late leaves the base further on for good): `Plan.allowances`, until a move to an
absolute place that the device finished puts it where the recording had it (`Plan.arrivals`)."""
from __future__ import annotations

import bisect
import math
import statistics
from dataclasses import dataclass, field
from typing import Any, Callable

from acti_record.calls import Call
from acti_record.reading import Message


@dataclass
class ClockMap:
    """A job's simulated time at moments of its wall clock, from the /clock messages it
    published (source timestamp: wall ns; contents: simulated ns), added in order. Between two
    messages the time is interpolated; past the last it runs on at the job's own rate."""
    walls: list[int] = field(default_factory=list)
    sims: list[int] = field(default_factory=list)

    def add(self, wall_ns: int, sim_ns: int) -> None:
        if not self.walls or wall_ns > self.walls[-1] and sim_ns >= self.sims[-1]:
            self.walls.append(wall_ns)
            self.sims.append(sim_ns)

    def rate(self) -> float:
        """Simulated seconds per wall second over the map (1 without two messages)."""
        span = self.walls[-1] - self.walls[0] if self.walls else 0
        return (self.sims[-1] - self.sims[0]) / span if span > 0 else 1.0

    def sim_at(self, wall_ns: int) -> float:
        """The simulated time [ns] at wall_ns (wall_ns itself with no /clock at all)."""
        if not self.walls:
            return float(wall_ns)
        i = bisect.bisect_right(self.walls, wall_ns)
        if i == 0 or i == len(self.walls):
            edge = 0 if i == 0 else -1
            return self.sims[edge] + (wall_ns - self.walls[edge]) * self.rate()
        w0, w1, s0, s1 = self.walls[i - 1], self.walls[i], self.sims[i - 1], self.sims[i]
        return s0 + (s1 - s0) * (wall_ns - w0) / (w1 - w0)

    def period_ns(self) -> float:
        """The simulated time between two messages (the median): the map's resolution."""
        steps = [b - a for a, b in zip(self.sims, self.sims[1:]) if b > a]
        return statistics.median(steps) if steps else 0.0


@dataclass
class SpeedTrack:
    """A device's recorded speed over simulated time, in the units of its answers per second
    (mm/s, degree/s: the larger)."""
    times: list[int] = field(default_factory=list)
    speeds: list[float] = field(default_factory=list)

    def add(self, sim_ns: float, speed: float) -> None:
        i = bisect.bisect_right(self.times, sim_ns)
        self.times.insert(i, sim_ns)
        self.speeds.insert(i, abs(speed))

    def departure(self, t0: float, t1: float, by: float) -> float | None:
        """When the speed, after t0 and before t1, first leaves its value at t0 (by more than
        `by`): where that change, extended back along its first two samples, began (a ramp's
        start, whatever the samples' phase); None when it does not."""
        i = max(bisect.bisect_right(self.times, t0) - 1, 0)
        if not self.times:
            return None
        v0 = self.speeds[i]
        for j in range(i + 1, len(self.times)):
            t, v = self.times[j], self.speeds[j]
            if t >= t1:
                return None
            if abs(v - v0) > by:
                if j + 1 < len(self.times) and (self.speeds[j + 1] - v) * (v - v0) > 0:
                    slope = (self.speeds[j + 1] - v) / (self.times[j + 1] - t)
                    return max(t - (v - v0) / slope, t0)
                return t
        return None

    def settled(self, t0: float, t1: float, by: float) -> float | None:
        """When the device came to rest after moving, after t0, to stay at rest (within `by`)
        until t1: the first sample of that rest; None when it did not move after t0 or was still
        moving before t1."""
        i0, i1 = bisect.bisect_right(self.times, t0), bisect.bisect_left(self.times, t1)
        moving = [j for j in range(i0, i1) if self.speeds[j] > by]
        if not moving or moving[-1] + 1 >= i1:
            return None
        return self.times[moving[-1] + 1]

    def peak(self, t0: float, t1: float) -> float:
        """The highest speed from t0 to t1, the samples on either side included."""
        i0 = max(bisect.bisect_left(self.times, t0) - 1, 0)
        i1 = bisect.bisect_right(self.times, t1) + 1
        return max(self.speeds[i0:i1], default=0.0)


NEVER = float("-inf")
ARRIVAL = "arrival"         # an arrival's mark among an allowance's events (not an input)

# Moves whose end is a place of their own, whatever the start (the arm's elbow is given with a
# Cartesian target; the base's target has its heading): once one is over, its device is where the
# recording had it. Not the base's cruise: its end heading follows the path from the start.
ABSOLUTE_MOVES = frozenset({"move_ptp_joint_abs", "move_ptp_cartesian_abs",
                            "move_linear_cartesian_abs", "move_circular_cartesian_abs", "go_home",
                            "move_linear_abs"})
WAITS = frozenset({"wait_motion"})          # actions that only wait for a device


def operation_of(service: str) -> str:
    """The operation a service (an action's too) serves: its last name."""
    return service.split("/_action/", 1)[0].rsplit("/", 1)[-1]


def is_command(service: str) -> bool:
    """A call that may change what its device does: anything but a getter or a wait."""
    name = operation_of(service)
    return not (name.startswith("get_") or name in WAITS)


def accepted(response: Any) -> bool:
    """The recorded answer accepted the request: the arm's RETURN_ID OK, the base's true."""
    return_id = getattr(response, "return_id", None)
    if return_id is not None:
        return return_id.id == 0
    return bool(getattr(response, "success", False))


class Plan:
    """What a replay sends, in the recorded order: the calls (`acti_record.calls`) and the
    messages of command topics, each an input of its device; the events they make (a request
    taken, an answer sent, a message published), on the recording's clock; for each input, the
    answers it waits for (those given before it in the recording) and its anchor, the event
    right before it, from which its recorded offset is kept."""

    def __init__(self, calls: list[Call], commands: list[Message], device_of_call: Callable[[Call], str],
                 device_of_topic: dict[str, str], clock: ClockMap) -> None:
        self.recorded_ns: list[int] = []                       # each event's, wall
        self.request_event = [self._event(c.request_ns) for c in calls]
        self.answer_event = [None if c.response_ns is None else self._event(c.response_ns)
                             for c in calls]
        self.call_of_request = {e: k for k, e in enumerate(self.request_event)}
        self.call_of_answer = {e: k for k, e in enumerate(self.answer_event) if e is not None}
        items = [(c.request_ns, "call", k, self.request_event[k], device_of_call(c))
                 for k, c in enumerate(calls)]
        items += [(m.publish_ns, "message", k, self._event(m.publish_ns),
                   device_of_topic[m.channel.topic]) for k, m in enumerate(commands)]
        items.sort(key=lambda item: (item[0], item[3]))
        self.inputs = [(kind, k) for _, kind, k, _, _ in items]
        self.nth_of_service = [sum(1 for earlier in calls[:k] if earlier.service == c.service)
                               for k, c in enumerate(calls)]
        self.input_of = {k: n for n, (kind, k) in enumerate(self.inputs) if kind == "call"}
        # per input: it may change what its device does (a command message always may), and
        # it is an accepted move to an absolute place
        self.commanding = [kind == "message" or is_command(calls[k].service)
                           for kind, k in self.inputs]
        self.absolute = [kind == "call" and operation_of(calls[k].service) in ABSOLUTE_MOVES
                         and accepted(calls[k].response) for kind, k in self.inputs]
        self.event_of = [event for *_, event, _ in items]
        self.devices = [device for *_, device in items]
        self.sim_ns = [clock.sim_at(t) for t in self.recorded_ns]
        order = sorted(range(len(self.recorded_ns)), key=lambda e: (self.recorded_ns[e], e))
        rank = {e: r for r, e in enumerate(order)}
        self.anchors = [order[rank[e] - 1] if rank[e] else None for e in self.event_of]
        self.waits = [{k for k, a in enumerate(self.answer_event)
                       if a is not None and self.recorded_ns[a] <= self.recorded_ns[e]}
                      for e in self.event_of]

    def _event(self, recorded_ns: int) -> int:
        self.recorded_ns.append(recorded_ns)
        return len(self.recorded_ns) - 1

    def due_ns(self, n: int, job_wall_ns: dict[int, int], job_clock: ClockMap,
               rate: float) -> float:
        """When input n is due on the job's simulated clock: its anchor's time there plus its
        recorded offset from it (NEVER: at once, when it has no anchor)."""
        anchor = self.anchors[n]
        if anchor is None or anchor not in job_wall_ns:
            return NEVER
        return job_clock.sim_at(job_wall_ns[anchor]) + \
            (self.sim_ns[self.event_of[n]] - self.sim_ns[anchor]) / rate

    def errors_s(self, job_wall_ns: dict[int, int], job_clock: ClockMap,
                 rate: float) -> list[float]:
        """Each input's timing error [s] on the job's simulated clock: how much later (< 0:
        earlier) than its recorded offset from its anchor the job had it in the replay."""
        errors = []
        for n, event in enumerate(self.event_of):
            anchor = self.anchors[n]
            if anchor is None or anchor not in job_wall_ns or event not in job_wall_ns:
                errors.append(0.0)
                continue
            replayed = job_clock.sim_at(job_wall_ns[event]) - job_clock.sim_at(job_wall_ns[anchor])
            errors.append((replayed - (self.sim_ns[event] - self.sim_ns[anchor]) / rate) / 1e9)
        return errors

    def reaction_errors(self, device: str, recorded: SpeedTrack, replayed: SpeedTrack,
                        job_wall_ns: dict[int, int], job_clock: ClockMap,
                        by: float) -> list[tuple[float, float]]:
        """The device's own timing: after each of its inputs (before the next), when its
        speed began to change (`SpeedTrack.departure`: a start, a stop's braking, a jog's end),
        measured from when the job took the input, in both runs. For each input it changed
        after in both: the change's recorded time and how much later it came in the replay
        [s] (the job reacting later: a stop planned longer under load)."""
        mine = [n for n, d in enumerate(self.devices) if d == device]
        out = []
        for k, n in enumerate(mine):
            event = self.event_of[n]
            later = self.event_of[mine[k + 1]] if k + 1 < len(mine) else None
            if event not in job_wall_ns:
                continue
            t_rec, t_rep = self.sim_ns[event], job_clock.sim_at(job_wall_ns[event])
            end_rec = self.sim_ns[later] if later is not None else math.inf
            end_rep = job_clock.sim_at(job_wall_ns[later]) if later in job_wall_ns else math.inf
            rec = recorded.departure(t_rec, end_rec, by)
            rep = replayed.departure(t_rep, end_rep, by)
            if rec is not None and rep is not None:
                out.append((rec, ((rep - t_rep) - (rec - t_rec)) / 1e9))
        return out

    def arrivals(self, device: str, track: SpeedTrack, by: float) -> list[float]:
        """When the device, in the recording, came to rest at the end of an accepted move to an
        absolute place (`ABSOLUTE_MOVES`) and stayed there until its next command (`SpeedTrack.
        settled`): from then on it is where the recording had it, whatever the timing before.
        A stop or another move before it rested (a command) ends nothing."""
        mine = [n for n, d in enumerate(self.devices) if d == device and self.commanding[n]]
        out = []
        for k, n in enumerate(mine):
            if self.absolute[n]:
                t1 = self.sim_ns[self.event_of[mine[k + 1]]] if k + 1 < len(mine) else math.inf
                rest = track.settled(self.sim_ns[self.event_of[n]], t1, by)
                if rest is not None:
                    out.append(rest)
        return out

    def allowances(self, errors_s: list[float], peak_speed: Callable[[str, float, float], float],
                   margin_s: float, reactions: dict[str, list[tuple[float, float]]] | None = None,
                   arrivals: dict[str, list[float]] | None = None) -> list[float]:
        """For each input, how far its device may be from where the recording had it once the
        input is made: the sum, over the device's timed events up to this one (its inputs and
        its reactions, `reaction_errors`), of (|error| + margin_s) times the
        device's highest recorded speed from the event before to the event after (while that
        event's timing can matter); a timing error moves a device for good (a stop given late
        leaves the base further on). An arrival at an absolute place (`arrivals`) ends it: the
        device's events from then on start from nothing, once the replay's device has arrived
        too (it may run late by the sum of its timing errors so far, margins included) and
        unless a command of it came before that."""
        events = [(self.sim_ns[e], n, device, errors_s[n])
                  for n, (e, device) in enumerate(zip(self.event_of, self.devices))]
        events += [(t, None, device, error) for device, found in (reactions or {}).items()
                   for t, error in found]
        events += [(t, ARRIVAL, device, 0.0) for device, found in (arrivals or {}).items()
                   for t in found]
        events.sort(key=lambda item: item[0])
        own: dict[str, list[tuple]] = {}
        for event in events:
            own.setdefault(event[2], []).append(event)
        drift: dict[str, float] = {}
        late: dict[str, float] = {}             # the device's timing errors so far, s
        over: dict[str, float] = {}             # its drift is over for events from then on
        out = [0.0] * len(self.event_of)
        for event in events:
            t, n, device, error = event
            if n == ARRIVAL:
                over[device] = t + late.get(device, 0.0) * 1e9
                continue
            if device in over and (t >= over[device] or n is not None and self.commanding[n]):
                if t >= over[device]:
                    drift[device] = late[device] = 0.0
                del over[device]        # a command before the replay's device surely arrived
            mine = own[device]
            k = mine.index(event)
            t0 = mine[k - 1][0] if k else t
            t1 = mine[k + 1][0] if k + 1 < len(mine) else t
            drift[device] = drift.get(device, 0.0) + \
                peak_speed(device, t0, t1) * (abs(error) + margin_s)
            late[device] = late.get(device, 0.0) + abs(error) + margin_s
            if n is not None:
                out[n] = drift[device]
        return out
