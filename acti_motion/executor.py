"""The shared motion-queue executor: one simulation thread, one bounded FIFO per device.

Cores (arm, vehicle) plan motions on their own threads and hand finished `Motion`s to a `Device`.
The simulation thread steps the world at a fixed rate and advances each device's current motion.
Pause, resume and stop never wait for planning: they only change the device's time rate, which the
simulation thread ramps linearly, so every motion decelerates along its own path.
"""
from __future__ import annotations

import contextlib
import logging
import math
import threading
import time
from collections import deque
from dataclasses import dataclass
from typing import Any, Callable, Iterator, Protocol, Sequence

from acti_sim.world import World

_log = logging.getLogger("acti_motion")


class Motion(Protocol):
    """A planned motion: what to command at time t (s) into it, and the set-point there."""
    duration: float

    def apply(self, world: World, t: float, rate: float) -> None:
        """Command the world for time t; `rate` scales the feed-forward velocity (0 when held)."""

    def at(self, t: float) -> Any:
        """The set-point at time t (the device's own kind: joint vector, pose …)."""


STALE = object()       # Device.edit_planned: the plan came too late, plan again
STOPPED = "stop"       # why a stop discards, unless its caller says


@dataclass
class QueuedMotion:
    id: int
    motion: Motion
    label: str


class DiscardLog:
    """Which motion ids were discarded, for every id ever given (one bit each), and why, for the
    last REASONS_KEPT discards (the reasons of older ones are no longer said)."""

    REASONS_KEPT = 256
    FORGOTTEN = "discarded (why is no longer kept: too many stops since)"

    def __init__(self) -> None:
        self._bits = bytearray()
        self._reasons: deque[tuple[int, int, str]] = deque(maxlen=self.REASONS_KEPT)

    def add(self, first: int, last: int, reason: str) -> None:
        """Ids first … last were discarded, because of `reason`. Whole bytes are set at once: a
        stop discards the queue under the lock the simulation step takes, and id by id a queue
        of 100 000 took 8 ms there."""
        need = last // 8 + 1
        if need > len(self._bits):
            self._bits.extend(bytes(max(need - len(self._bits), len(self._bits))))
        whole_from, whole_to = (first + 7) >> 3, (last + 1) >> 3     # bytes all inside the range
        if whole_from >= whole_to:
            self._set(first, last + 1)
        else:
            self._set(first, whole_from << 3)
            self._bits[whole_from:whole_to] = b"\xff" * (whole_to - whole_from)
            self._set(whole_to << 3, last + 1)
        self._reasons.append((first, last, reason))

    def _set(self, start: int, stop: int) -> None:
        for motion_id in range(start, stop):
            self._bits[motion_id >> 3] |= 1 << (motion_id & 7)

    def reason(self, motion_id: int) -> str | None:
        """Why motion `motion_id` was discarded, None if it was not."""
        if not (0 <= motion_id >> 3 < len(self._bits)
                and self._bits[motion_id >> 3] >> (motion_id & 7) & 1):
            return None
        return next((why for lo, hi, why in reversed(self._reasons) if lo <= motion_id <= hi),
                    self.FORGOTTEN)


class Device:
    """One bounded FIFO of motions with pause/resume/stop by time scaling.

    Motion ids grow by one per accepted motion; `retired_id` is the highest id that finished or
    was discarded, so "is motion n over?" is `retired_id >= n` (the queue is FIFO).
    """

    def __init__(self, name: str, capacity: int, hold: Any) -> None:
        self.name = name
        self.capacity = capacity
        self.hold = hold
        self.queued_end = hold
        self._accept = threading.Lock()
        self.lock = threading.Lock()
        self.queue: deque[QueuedMotion] = deque()
        self.current: QueuedMotion | None = None
        self.t = 0.0
        self.rate = 1.0
        self._rate_target = 1.0
        self._ramp = 1.0
        self._stop_at: float | None = None
        self._cap = 1.0            # the highest rate allowed now (`cap_rate`)
        self._cap_ramp = 1.0
        self._stops = 0            # stops asked for (`arrival`, `stopped_since`)
        self.paused = False
        self.generation = 0
        self.revision = 0          # bumped whenever the motions change, except by time passing
        self.last_id = 0
        self.retired_id = 0
        self.completed = 0
        self.discarded = 0
        self._discards = DiscardLog()     # what stops, halts and take-overs discarded
        self._reason = STOPPED      # why the present stop discards (a motion arriving meanwhile)
        self._retire_listeners: list[Callable[[], None]] = []
        self.wake: Callable[[], None] = lambda: None    # the loop: work came (`MotionExecutor`)

    # --- called by cores (any thread) -------------------------------------------------------
    @property
    def moving(self) -> bool:
        return self.current is not None

    @property
    def busy(self) -> bool:
        """Something is running or waiting to run."""
        return self.current is not None or bool(self.queue)

    @property
    def stopping(self) -> bool:
        """A stop is decelerating the current motion."""
        return self._stop_at is not None

    @property
    def queue_length(self) -> int:
        return len(self.queue)

    @property
    def full(self) -> bool:
        return len(self.queue) >= self.capacity

    @property
    def idle(self) -> bool:
        """Nothing runs or waits to run: the loop has nothing to command it."""
        return self.current is None and not self.queue

    def motion_state(self) -> tuple[bool, bool, bool]:
        """(moving, paused, full), read together under the lock, so that a state word made of
        them is one moment's: read apart, a stop between two reads made a paused arm at rest
        look moving. Moving: the current motion's clock runs or is to run (its rate, or the
        rate it ramps to, is above 0: a motion paused or stopped at rest is not moving), or a
        motion waits to start and no pause holds it."""
        with self.lock:
            cur = self.current
            moving = (self.rate > 0.0 or self._rate_target > 0.0) if cur is not None \
                else bool(self.queue) and not self.paused
            return moving, self.paused, len(self.queue) >= self.capacity

    def submit(self, plan: Callable[[Any], Motion], label: str) -> int | None:
        """Plan a motion from the end of the last queued one and append it; its id, or None when
        the queue is full (`submit_all` of one)."""
        got = self.submit_doomed([(plan, label)])
        return None if got is None else got[0][0]

    def submit_all(self, plans: Sequence[tuple[Callable[[Any], Motion], str]]) -> list[int] | None:
        """Plan motions one after the other, each from the end of the one before (the first from
        the end of the last queued), and append them together: their ids, or None when the queue
        has no room for all of them (then nothing is queued). Planning runs on the caller's
        thread, never under the lock that pause, stop and the simulation take. Exceptions of a
        plan (a refusal) pass through and queue nothing: a sequence goes in whole or not at all.

        A stop discards every command accumulated until the device is at rest (ACT 5.4.19;
        the vehicle's 停止後は全ての動作指令を廃棄): motions that arrive while a stop decelerates,
        or whose planning a stop (or halt) overtook, are accepted (they get ids) and discarded
        when the device comes to rest, or at once when it already rests; `was_discarded(id)`
        says so, and nothing of them runs. They arrive when this is called: planned, or waiting
        for another's plan, across the end of a stop, they were queued after it and ran.
        """
        got = self.submit_doomed(plans)
        return None if got is None else got[0]

    def submit_doomed(self, plans: Sequence[tuple[Callable[[Any], Motion], str]]
                      ) -> tuple[list[int], str | None] | None:
        """`submit_all`'s ids with why the last is doomed (`doomed`), read in the same hold
        (a move's accept takes the lock once less); None when the queue is full."""
        arrived = None          # nobody else plans: it arrives in the hold that reads the queue
        if not self._accept.acquire(blocking=False):
            arrived = self.arrival()                # it arrives now, before it waits its turn
            self._accept.acquire()
        try:
            while True:
                with self.lock:
                    if arrived is None:
                        arrived = self._stops - (self._stop_at is not None)     # `arrival`
                    if len(self.queue) + len(plans) > self.capacity:
                        return None
                    generation, start = self.generation, self.queued_end
                motions = []
                for plan, _ in plans:
                    if motions:                     # from the end of the one before
                        start = motions[-1].at(motions[-1].duration)
                    motions.append(plan(start))
                with self.lock:
                    if len(self.queue) + len(plans) > self.capacity:
                        return None
                    if generation != self.generation or self._stops != arrived:  # `stopped_since`
                        if self.current is None and not self.queue:
                            ids = [self._accept_discarded() for _ in plans]
                            return ids, self._doomed(ids[-1]) if ids else None
                        if self._stop_at is None:
                            continue        # a halt's own motion runs: plan again from its end
                    ids = []
                    was_idle = self.current is None and not self.queue
                    for motion, (_, label) in zip(motions, plans):
                        self.last_id += 1
                        if motion.duration <= 0.0 and self.idle and not self.paused:
                            self._complete_at_once(motion)
                        else:
                            self.queue.append(QueuedMotion(self.last_id, motion, label))
                        ids.append(self.last_id)
                    self.revision += 1
                    if self._stop_at is None:
                        self.queued_end = self._end_of_queue()
                    if was_idle and self.queue:
                        # work for a loop that may sleep (a busy device's loop steps on); a
                        # motion over at once is none: an idle loop woken for it stepped the
                        # steps it slept over while the answer went out
                        self.wake()
                    # ids given now, none discarded yet: doomed only by a stop decelerating
                    # (`_doomed`; a device at rest has none, and a motion over at once rests it)
                    return ids, self._reason if ids and self._stop_at is not None else None
        finally:
            self._accept.release()

    def arrival(self) -> int:
        """A mark of now for `stopped_since`: a stop that decelerates now counts as one to come
        (what arrives during its deceleration is discarded with what came before it)."""
        with self.lock:
            return self._stops - (self._stop_at is not None)

    def stopped_since(self, mark: int) -> bool:
        """A stop came after `arrival()` gave `mark`, or was decelerating then."""
        return self._stops != mark

    def pause(self, ramp: float, idle: bool = True, after_stop: bool = False) -> bool:
        """Decelerate over `ramp` seconds and hold (also what is queued and not yet started);
        the queue stays. False when already paused or stopping (a stop clears a pause), and,
        unless `idle`, when nothing runs or is queued: checked here, under the lock a stop takes
        (a stop or servo_off between the caller's check and this left an idle arm paused).
        `after_stop`: a pause given while a stop decelerates holds once the stop is over (the
        stop's ramp runs on), instead of being refused."""
        with self.lock:
            stopping = self._stop_at is not None
            if self.paused or (stopping and not after_stop) or not (idle or self.busy):
                return False
            self.paused = True
            if not stopping:
                self._set_rate(0.0, ramp)
            return True

    def resume(self, ramp: float) -> bool:
        """Undo a pause, accelerating over `ramp` seconds (one given during a stop only stops
        holding: the stop's ramp runs on). False when not paused."""
        with self.lock:
            if not self.paused:
                return False
            self.paused = False
            if self._stop_at is None:
                self._set_rate(1.0, ramp)
            return True

    def stop(self, ramp: float, reason: str = STOPPED) -> None:
        """Discard the queue, clear a pause and decelerate the current motion over `ramp` seconds.

        The rate falls linearly, so the motion's clock advances rate² · ramp / 2 more seconds: the
        rest point is known now and becomes the start of whatever is queued next. A stop while
        one decelerates keeps the shorter ramp and computes the rest point again from the rate
        now, so the clock never jumps to a rest point meant for another ramp. An infinite ramp
        keeps the rate: the motion runs on at its pace to its end, the rest point.
        """
        with self.lock:
            self._reason = reason
            self._stops += 1
            self._discard_pending()
            cur = self.current
            if cur is None:
                self.rate = self._rate_target = 1.0
            elif self.rate <= 0.0:
                # at rest (a pause held it): nothing decelerates, so the stop is over now. Left
                # to the next step, a move accepted before it was discarded as if it had come
                # during a deceleration, which a busy machine made tens of ms long.
                self._finish(discarded=True)
            else:
                if self._stop_at is None:
                    # a move cut short to hand over to the next (a blend) stops along its whole path
                    cur.motion = getattr(cur.motion, "unblended", cur.motion)
                else:
                    ramp = min(ramp, self._ramp)
                self._stop_at = min(cur.motion.duration, self.t + self.rate * self.rate * ramp / 2)
                self._set_rate(0.0, ramp)
            self.queued_end = self._end_of_queue()

    def cap_rate(self, cap: float, ramp: float) -> None:
        """Let the motion's clock run at most `cap` times its pace (a speed limit that keeps the
        path), ramping there over `ramp` s per unit of rate; 1.0 lifts it. Pause, resume and stop
        keep their own targets below it."""
        with self.lock:
            self._cap = min(max(cap, 0.0), 1.0)
            self._cap_ramp = max(ramp, 1e-6)

    def edit(self, fn: Callable[["Device"], Any]) -> Any:
        """Run fn(device) under the lock and return its result: a core changes its motions in place
        there (the current one from time `t` on, queued ones whole, or the rest point `hold`)
        without racing the simulation; the queued end then follows the last motion."""
        with self.lock:
            out = fn(self)
            self.revision += 1
            self.queued_end = self._end_of_queue()
            self.wake()
            return out

    def edit_planned(self, look: Callable[["Device", int], Any],
                     plan: Callable[[Any], Callable[["Device"], Any]], tries: int = 6) -> Any:
        """An edit whose planning runs under no lock, so the simulation never waits for it.

        look(device, attempt) runs under the lock and takes what the plan needs (say, the
        reference state a little ahead of now: the further the more attempts failed);
        plan(seen) runs under no lock and returns commit(device), which runs under the lock
        only if no motion was queued, started, finished, edited or stopped meanwhile, and may
        itself answer STALE (the device has passed the planned splice time). Either way it
        looks and plans again, at most `tries` times; then STALE. Callers serialise their own
        planning (an edit or a stop that comes in meanwhile only costs a retry).
        """
        for attempt in range(tries):
            with self.lock:
                seen_at = (self.generation, self.revision)
                seen = look(self, attempt)
            commit = plan(seen)
            with self.lock:
                if seen_at != (self.generation, self.revision):
                    continue
                out = commit(self)
                if out is STALE:
                    continue
                self.revision += 1
                self.queued_end = self._end_of_queue()
                self.wake()
                return out
        return STALE

    def discard_queue(self, reason: str = STOPPED) -> None:
        """Discard the queued motions (not the current one), for an edit that changes where the
        current one ends; the lock must be held (call it from an edit)."""
        self.generation += 1
        self._reason = reason
        self._retire_queue()

    def halt(self, rest: Any, reason: str, then: tuple[Motion, str] | None = None) -> None:
        """Discard the current motion and the queue at once and rest at `rest` (where the device
        is, as measured): for a device that cannot follow its plan (blocked, a contact). `then`
        (motion, label) is queued at once, as the only motion (a brake): through `submit` it
        would wait for whoever plans, and the simulation thread that halts must never wait."""
        with self.lock:
            self._reason = reason
            self._discard_pending()
            if self.current is not None:
                self._finish(discarded=True)
            self._stop_at = None
            self.rate = self._rate_target = 1.0
            self.hold = self.queued_end = rest
            if then is not None:
                self.last_id += 1
                self.revision += 1
                self.queue.append(QueuedMotion(self.last_id, *then))
                self.queued_end = self._end_of_queue()
            self.wake()

    @contextlib.contextmanager
    def idle_for_settings(self) -> Iterator[bool]:
        """Planning held off while the caller changes what plans read (the arm's frames); yields
        whether nothing runs, is queued or is being planned. Never waits: a plan under way (it
        holds the accept lock) answers False, and one that comes waits the few microseconds
        the caller takes."""
        if not self._accept.acquire(blocking=False):
            yield False
            return
        try:
            yield not self.busy
        finally:
            self._accept.release()

    def renumber(self, entry: QueuedMotion, reason: str) -> int:
        """(lock held) The running motion `entry`, taken over by a command with another goal,
        goes on as that command's motion: its old id retires as discarded (it never reached its
        end, so a wait on it says not completed) and it runs on under a new id, returned."""
        self.discarded += 1
        self._discards.add(entry.id, entry.id, reason)
        self.retired_id = max(self.retired_id, entry.id)
        self.last_id += 1
        entry.id = self.last_id
        self.revision += 1
        self._announce_retired()
        return entry.id

    def is_over(self, motion_id: int) -> bool:
        """Motion `motion_id` finished or was discarded. `retired_id` alone is not enough: a stop
        retires the queue behind the current motion at once while the current one still
        decelerates."""
        current = self.current
        return self.retired_id >= motion_id and (current is None or current.id != motion_id)

    def on_retire(self, fn: Callable[[], None]) -> None:
        """Call fn() whenever motions retire (finish or are discarded): how waiters that hold no
        thread (the action servers) learn of it. It runs on the retiring thread with the lock
        held, so it must only signal (never block, never call back into the device)."""
        self._retire_listeners.append(fn)

    def was_discarded(self, motion_id: int) -> bool:
        """True when motion `motion_id` was discarded (by a stop, a halt or a take-over)."""
        return self.discard_reason(motion_id) is not None

    def discard_reason(self, motion_id: int) -> str | None:
        """Why motion `motion_id` was discarded ("stop", "servo off" …), None if it was not."""
        with self.lock:
            return self._discards.reason(motion_id)

    def doomed(self, motion_id: int) -> str | None:
        """Why motion `motion_id` is, or will be, discarded: retired so, or accepted while a
        stop decelerates (it goes when the device rests); None otherwise."""
        with self.lock:
            return self._doomed(motion_id)

    def _doomed(self, motion_id: int) -> str | None:
        why = self._discards.reason(motion_id)
        if why is None and self._stop_at is not None and motion_id > self.retired_id:
            why = self._reason
        return why

    def status(self) -> tuple[int, str, float, int]:
        """(current motion id or 0, its label, its completed fraction, motions queued behind)."""
        cur = self.current
        if cur is None:
            return 0, "", 0.0, len(self.queue)
        d = cur.motion.duration
        return cur.id, cur.label, 1.0 if d <= 0 else min(1.0, self.t / d), len(self.queue)

    # --- called by the simulation thread -----------------------------------------------------
    def tick(self, world: World, dt: float) -> None:
        with self.lock:
            if self.current is None:
                if self.paused or not self.queue:
                    return
                self.current = self.queue.popleft()
                self.revision += 1
                self.t = 0.0
            t0 = self.t
            try:
                self._advance(world, dt)
            except Exception as e:
                self._fail(e, t0)

    def _next_rate(self, dt: float) -> float:
        """The rate after one more step of `dt`: it ramps linearly towards its target (or
        towards the cap, over the cap's ramp, where that is lower: `cap_rate`)."""
        r0 = self.rate
        target, ramp = self._rate_target, self._ramp
        if self._cap < target:
            target, ramp = self._cap, self._cap_ramp
        step = dt / ramp if ramp > 0 else 1.0
        return min(target, r0 + step) if r0 < target else max(target, r0 - step)

    def rest_time_after_next_step(self, ramp: float, dt: float) -> float:
        """The current motion's clock time where it would rest if a stop over `ramp` seconds
        began after the next step (clock and rate then, as `stop` computes the rest point):
        what the watch looks ahead to. Called on the simulation thread, the one that advances
        the clock and the rate, so they are read together."""
        cur = self.current
        if cur is None:
            return self.t
        r1 = self._next_rate(dt)
        t1 = self.t + dt * (self.rate + r1) / 2
        return min(cur.motion.duration, t1 + r1 * r1 * ramp / 2)

    def stop_at(self, t_rest: float, shortest_ramp: float, reason: str = STOPPED) -> None:
        """`stop` with the ramp that rests the current motion at clock time `t_rest`, or with
        `shortest_ramp` when that rests it later (the fastest stop allowed)."""
        r = self.rate
        ramp = 2.0 * (t_rest - self.t) / (r * r) if r > 0.0 else shortest_ramp
        self.stop(max(ramp, shortest_ramp), reason)

    def _advance(self, world: World, dt: float) -> None:
        """One step of the current motion: ramp the rate, advance its clock, command the world."""
        r0 = self.rate
        r1 = self._next_rate(dt)
        self.rate = r1
        self.t += dt * (r0 + r1) / 2
        cur = self.current
        if self._stop_at is not None and (r1 <= 0.0 or self.t >= self._stop_at):
            self.t = self._stop_at
            cur.motion.apply(world, self.t, 0.0)
            self._finish(discarded=True)
            self._retire_queue()            # what came in while it decelerated
            self.queued_end = self.hold
            return
        end = self.t >= cur.motion.duration
        if end and hasattr(cur.motion, "unblended") and self.queue:
            # cut to hand over at speed (a blend): the next motion goes on in this same step,
            # from the time past the seam, also while a pause decelerates (no halt there)
            past = self.t - cur.motion.duration
            self._finish(discarded=False)
            cur = self.current = self.queue.popleft()
            self.t = past
            end = self.t >= cur.motion.duration
        cur.motion.apply(world, min(self.t, cur.motion.duration), 0.0 if end else r1)
        if end:
            self._finish(discarded=False)

    # --- internals (lock held) ---------------------------------------------------------------
    def _fail(self, error: Exception, t0: float) -> None:
        """A motion that fails while it runs (a bug, a plan no check foresaw) is discarded with
        the queue where its last step put it; the simulation steps on and the process stays."""
        cur = self.current
        what = f"motion {cur.id} ({cur.label}) failed at {t0:.3f} s" if cur else "a step failed"
        _log.error(f"{self.name}: {what}, discarded with the queue: {type(error).__name__}: {error}")
        self._reason = f"a failure of {cur.label if cur else 'a step'}"
        self._discard_pending()
        if cur is not None:
            self.t = t0
            self._finish(discarded=True)
        self.queued_end = self.hold

    def _set_rate(self, target: float, ramp: float) -> None:
        self._rate_target = target
        self._ramp = max(ramp, 1e-6)

    def _finish(self, discarded: bool) -> None:
        assert self.current is not None
        self.hold = self.current.motion.at(self.t)
        self.retired_id = max(self.retired_id, self.current.id)
        if discarded:
            self.discarded += 1
            self._discards.add(self.current.id, self.current.id, self._reason)
            self._stop_at = None
            self.rate = self._rate_target = 1.0
        else:
            self.completed += 1
        self.current = None
        if not self.queue:          # where it rests, as measured (a brake's end was a forecast)
            self.queued_end = self.hold
        self.revision += 1
        self._announce_retired()

    def _end_of_queue(self) -> Any:
        """Where the device rests once everything queued now is over (a stop's rest point when
        the current motion is stopping): the start of the next motion submitted."""
        last = self.queue[-1] if self.queue else self.current
        if last is None:
            return self.hold
        if last is self.current and self._stop_at is not None:
            return last.motion.at(self._stop_at)
        return last.motion.at(last.motion.duration)

    def _complete_at_once(self, motion: Motion) -> None:
        """The motion just given an id takes no time on an idle device: it is over now, and the
        device rests at its end, as if a step had run it (queued, it held the device busy until
        a step picked it up)."""
        self.hold = self.queued_end = motion.at(motion.duration)
        self.completed += 1
        self.retired_id = max(self.retired_id, self.last_id)
        self._announce_retired()

    def _accept_discarded(self) -> int:
        """A new id, retired at once as discarded (a stop overtook it)."""
        self.last_id += 1
        self.discarded += 1
        self._discards.add(self.last_id, self.last_id, self._reason)
        self.retired_id = max(self.retired_id, self.last_id)
        return self.last_id

    def _discard_pending(self) -> None:
        """Drop the queue and a pause; motions planned meanwhile plan again (new generation)."""
        self.generation += 1
        self._retire_queue()
        self.paused = False

    def _retire_queue(self) -> None:
        if self.queue:
            self.discarded += len(self.queue)
            self._discards.add(self.queue[0].id, self.queue[-1].id, self._reason)
            self.retired_id = max(self.retired_id, self.queue[-1].id)
            self.queue.clear()
            self._announce_retired()

    def _announce_retired(self) -> None:
        for fn in self._retire_listeners:
            fn()


StepListener = Callable[[World], None]


@dataclass
class _Listener:
    every: float        # steps between two calls, on average
    due: float          # the step count of the next call
    fn: StepListener
    on_time: Callable[[], bool] | None     # its steps are due on time, also while idle


class MotionExecutor:
    """Steps the world (at its own fixed time step) on a thread of its own, `real_time_factor`
    times faster than wall time (0: as fast as it can), and advances every device each step.

    A loop that falls more than BEHIND_REPORT_S behind its schedule (held up, not merely slow by
    a step) says so in the log, once per fall, as a real-time controller reports an overrun;
    it then steps back to back until it has caught up."""

    BEHIND_REPORT_S = 0.05
    # An idle loop (no device has a motion) wakes this often at most, and at once when a device
    # is given work; on waking it runs the steps that fell due back to back. Each wake costs
    # more than an idle step (the sleep, cold caches: ~3x a step's Python work), and a step that
    # commands nothing changes nothing by running later: the physics is the same step by step.
    IDLE_WAKE_S = 0.02
    # Woken by work, it first lets the thread that gave it answer (a move's accept: its reply
    # and send), then catches up: the steps it slept over, run back to back, held the core and
    # the GIL while that answer went out. They lie before the work came: running them this much
    # later changes nothing they command.
    WORK_GRACE_S = 0.001

    def __init__(self, world: World, real_time_factor: float = 1.0,
                 alive: Callable[[], bool] = lambda: True) -> None:
        """`alive` tells whether the host process still runs: once it says no, the thread ends
        and a step that failed because the host is shutting down (a closed publisher) is quiet."""
        self.world = world
        self._alive = alive
        self.dt = world.time_step
        self.real_time_factor = real_time_factor
        self.devices: dict[str, Device] = {}
        self._before: list[StepListener] = []
        self._after: list[_Listener] = []
        self._thread: threading.Thread | None = None
        self._running = threading.Event()
        self._work = threading.Event()      # a device was given work: an idle loop wakes
        self.steps = 0
        self.falls_behind = 0           # how often the loop fell BEHIND_REPORT_S behind
        self.error: Exception | None = None     # what ended the loop, if an error did
        self._behind = False

    def add_device(self, name: str, capacity: int, hold: Any) -> Device:
        """A motion queue whose device rests at set-point `hold` until its first motion."""
        device = Device(name, capacity, hold)
        device.wake = self._work.set
        self.devices[name] = device
        return device

    def before_step(self, fn: StepListener) -> None:
        """Run fn(world) on the simulation thread before the devices are advanced."""
        self._before.append(fn)

    def after_step(self, fn: StepListener, every: float = 1.0,
                   on_time: Callable[[], bool] | None = None) -> None:
        """Run fn(world) on the simulation thread after every `every`-th physics step. A
        fractional `every` alternates between the whole numbers around it, so that the rate is
        kept on average (100 Hz at 250 Hz: every 2, 3, 2, 3 … steps; rounding gave 125 Hz).
        While `on_time()` says so (a publication someone receives), an idle loop still wakes
        for each of fn's steps (`IDLE_WAKE_S`)."""
        every = max(1.0, every)
        self._after.append(_Listener(every, self.steps + every, fn, on_time))

    def steps_per_period(self, rate_hz: float) -> float:
        """The `every` of a listener that runs at rate_hz (at most once a step)."""
        return max(1.0, 1.0 / (rate_hz * self.dt))

    def step(self) -> None:
        """One control cycle: listeners, devices, physics. Used by the thread and by unit tests."""
        world = self.world
        for fn in self._before:
            fn(world)
        for device in self.devices.values():
            device.tick(world, self.dt)
        world.step()
        self.steps += 1
        for listener in self._after:
            if self.steps >= listener.due - 1e-9:
                listener.due += listener.every
                listener.fn(world)

    @property
    def running(self) -> bool:
        """Between start and shutdown, while the host process still runs."""
        return self._running.is_set() and self._alive()

    @property
    def failed(self) -> bool:
        """The loop ended on an error (`error`): nothing steps any more, so the host must end
        rather than go on answering as if the robot were controlled."""
        return self.error is not None

    def start(self, prepare: Callable[[], None] = lambda: None) -> None:
        """Step on a thread of its own, which first runs `prepare()` (the host sets that
        thread's scheduling there)."""
        self._running.set()
        self._thread = threading.Thread(target=self._loop, args=(prepare,), name="acti-sim",
                                        daemon=True)
        self._thread.start()

    def shutdown(self) -> None:
        self._running.clear()
        self._work.set()
        if self._thread is not None:
            self._thread.join(timeout=5.0)
            self._thread = None

    def _loop(self, prepare: Callable[[], None]) -> None:
        prepare()
        wall0 = time.monotonic()
        sim0 = self.world.time
        while self._running.is_set() and self._alive():
            try:
                self.step()
            except Exception as e:      # a bug in a step: the host sees `failed` and ends
                if self._alive():
                    self.error = e
                    _log.error(f"the control loop stopped: {type(e).__name__}: {e}")
                return
            ahead = 0.0
            if self.real_time_factor > 0:
                ahead = (self.world.time - sim0) / self.real_time_factor - (time.monotonic() - wall0)
                self._note_lateness(-ahead)
            self._work.clear()          # before looking: work given from now on wakes the wait
            idle_steps = self._idle_steps() if ahead > 0 else 0
            if idle_steps:
                if self._work.wait(ahead + idle_steps * self.dt / self.real_time_factor):
                    time.sleep(self.WORK_GRACE_S)
            else:
                # Sleeping (even 0 s) hands the GIL to service threads once per step.
                time.sleep(max(ahead, 0.0))

    def _idle_steps(self) -> int:
        """How many steps past the next an idle loop may sleep (0: not idle): none while a
        device has a motion, and none past a step of an on-time listener."""
        if not all(d.idle for d in self.devices.values()):
            return 0
        extra = int(self.IDLE_WAKE_S * self.real_time_factor / self.dt) - 1
        for listener in self._after:
            if extra > 0 and listener.on_time is not None and listener.on_time():
                extra = min(extra, math.ceil(listener.due - 1e-9) - self.steps - 1)
        return max(extra, 0)

    def _note_lateness(self, behind: float) -> None:
        """Report a fall behind the schedule once, when it begins; ready again once caught up."""
        if behind > self.BEHIND_REPORT_S and not self._behind:
            self._behind = True
            self.falls_behind += 1
            _log.warning(f"the control loop fell {behind * 1e3:.0f} ms behind real time (held "
                         "up: it steps back to back to catch up)")
        elif behind <= self.dt:
            self._behind = False
