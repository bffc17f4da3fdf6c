"""Stop always works: `stop`'s reply time and the time to rest of both devices of the main job
while (a) a long move is being planned, (b) the queue is full, (c) the most action goals are
held, (d) 8 client processes storm getters and moves, (e) a STROLIC program computes without
pause on the arm; and the largest /clock gap during each.

Each trial starts a motion, loads the job, calls a bare std_srvs/Trigger (the baseline, same
moment, same load) and then `stop`. Rest is when the stopped motion retires: when the job says
that a ~/wait_motion goal on it ended (the DDS source timestamp of that goal status), counted
from the call and, as the controller's own figure, from the job's answer to `stop` (the DDS
source timestamp of the response: the stop is in force when the job answers, so this leaves
out the request's way to the job, which a storm lengthens in this client's process); and, as
a third figure, when the goal's result reached this client (which adds this client's own
delays: a storm takes both cores from it too). /clock gaps likewise: as the job sent them and as they
arrived, beside the largest silence of a bare process that only publishes a Clock every control
period, scheduled as the job's loop (`clock_floor.py`): what the machine allowed in that case.
And `stop`'s time in the job: from its taking the request
(the REQUEST_RECEIVED service event, introspection on as by default) to its answer (the
response's source timestamp): what the control-plane rule bounds, free of this client's delays.
Ratios are against the bare round trip and the control period measured in
the same run (the /clock increment). Goals: stop reply p99 <= 3x bare, rest within the decel
time + 2 control periods, /clock never silent for more than 2 control periods. A trial whose
call went unanswered is counted as lost, beside the UDP datagrams the kernel dropped at full
socket receive buffers meanwhile (a client keeping fewer responses than the answers to other
clients that arrive before it takes its own loses it: the harness's keep 100, `CLIENT_QOS`).

    python bench/bench_control_plane.py            (a few minutes)
    python bench/bench_control_plane.py --cases cd (only cases (c) and (d))
    python bench/bench_control_plane.py --cases e  (only the program case)
    python bench/bench_control_plane.py --trials N (N trials per case and device, not 20: a
                                                    tail needs more)
    python bench/bench_control_plane.py --cases f  (busy processes at the job's niceness: as
                                                    other jobs on the machine, e.g. tests')
    python bench/bench_control_plane.py --storm S  (one storm client for S seconds: used by (d))
"""
from __future__ import annotations

import math
import os
import subprocess
import sys
import threading
import time
from contextlib import contextmanager, nullcontext
from dataclasses import dataclass
from typing import Any, Callable, Iterator

import numpy as np
from common import Actions, RosClient, bare_call, bare_trigger_answers, p, running

import rclpy
from acti_msgs import srv
from acti_msgs.action import RunProgram, VehicleWaitMotion, WaitMotion
from acti_msgs.msg import CarPosWithElbow, VehiclePoint
from action_msgs.msg import GoalStatus, GoalStatusArray
from rclpy.qos import DurabilityPolicy, QoSProfile
from rosgraph_msgs.msg import Clock
from service_msgs.msg import ServiceEventInfo

from acti_bringup.serving.adapter import CLIENT_QOS
from bench.clock_floor import FIFO_PRIORITY, NICENESS, TOPIC as BARE_CLOCK
from acti_bringup.serving.spinning import init, stop_requested

ARM, BASE = "/acti_middle_node/", "/vehicle_node/"
TRIALS = 20
MAX_GOALS = 4                       # max_action_goals and max_wait_goals of the job
QUEUE = 8                           # queue_size of both devices
STORM_CLIENTS = 8
BUSY_PROCESSES = 3                  # case (f): CPU-bound processes at the job's niceness
ARM_DECEL_S = 0.3                   # accel_time_joint
BASE_DECEL_S = 300.0 / 500.0        # default velocity / default acceleration (translation)


ANSWER_STAMPS: dict[int, float] = {}     # id(response) → its DDS source timestamp [s, wall]


def record_answer_stamps() -> None:
    """Keep the DDS source timestamp of every response this process takes (rclpy's executors
    drop the header): the job's own moment of answering."""
    from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
    take = _rclpy.Client.take_response

    def taking(handle: Any, response_type: type) -> Any:
        header, response = taken = take(handle, response_type)
        if header is not None:
            if len(ANSWER_STAMPS) > 10_000:
                ANSWER_STAMPS.clear()
            ANSWER_STAMPS[id(response)] = header.source_timestamp * 1e-9
        return taken
    _rclpy.Client.take_response = taking


class Background:
    """A second client node spun on a thread of its own: requests the main client does not wait
    for (the long plan of (a)) and the /clock arrival times."""

    def __init__(self) -> None:
        import rclpy
        from rclpy.executors import SingleThreadedExecutor
        self.node = rclpy.create_node("bench_background")
        self.clock_arrivals: list[float] = []       # here (monotonic)
        self.clock_sent: list[float] = []           # by the job (DDS source timestamp, wall)
        self.clock_values: list[float] = []
        self.node.create_subscription(Clock, "/clock", self._on_clock, 100)
        self.bare_clock_sent: list[float] = []      # by the bare publisher (source timestamp)
        self.node.create_subscription(
            Clock, BARE_CLOCK,
            lambda _m, info: self.bare_clock_sent.append(info["source_timestamp"] * 1e-9), 100)
        # when the job declared each goal of ~/wait_motion ended (DDS source timestamp, wall)
        self.goal_ended: dict[bytes, float] = {}
        status_qos = QoSProfile(depth=100, durability=DurabilityPolicy.TRANSIENT_LOCAL)
        for path in (ARM, BASE):
            self.node.create_subscription(GoalStatusArray, path + "wait_motion/_action/status",
                                          self._on_status, status_qos)
        # when the job took each stop request (its service event's stamp, wall), per service
        self.stops_taken: dict[str, list[float]] = {ARM + "stop": [], BASE + "stop": []}
        for name, stop in ((ARM + "stop", srv.Stop), (BASE + "stop", srv.VehicleStop)):
            self.node.create_subscription(
                stop.Event, name + "/_service_event",
                lambda e, taken=self.stops_taken[name]: taken.append(
                    e.info.stamp.sec + e.info.stamp.nanosec * 1e-9)
                if e.info.event_type == ServiceEventInfo.REQUEST_RECEIVED else None, 100)
        self.executor = SingleThreadedExecutor()
        self.executor.add_node(self.node)
        self._clients: dict[str, Any] = {}
        self._thread = threading.Thread(target=self.executor.spin, daemon=True)
        self._thread.start()

    def _on_clock(self, msg: Clock, info: dict) -> None:
        self.clock_arrivals.append(time.monotonic())
        self.clock_sent.append(info["source_timestamp"] * 1e-9)
        self.clock_values.append(msg.clock.sec + msg.clock.nanosec * 1e-9)

    def _on_status(self, msg: GoalStatusArray, info: dict) -> None:
        for s in msg.status_list:
            if s.status >= GoalStatus.STATUS_SUCCEEDED:
                self.goal_ended.setdefault(bytes(s.goal_info.goal_id.uuid),
                                           info["source_timestamp"] * 1e-9)

    def send(self, srv_type: type, name: str, **fields: Any) -> Any:
        client = self._clients.get(name) or self._clients.setdefault(
            name, self.node.create_client(srv_type, name, qos_profile=CLIENT_QOS))
        assert client.wait_for_service(timeout_sec=30.0)
        return client.call_async(srv_type.Request(**fields))

    def largest_clock_gaps(self, since: float, until: float) -> tuple[float, float, float]:
        """The largest gap between two /clock messages as the job sent them (their DDS source
        timestamps: the job's own silence) and as they arrived here (adding this client's
        delays: a storm takes both cores from it too); and the bare publisher's largest silence
        between the first and the last of those source timestamps."""
        n = len(self.clock_sent)                     # both lists grow on the spin thread
        arrived = np.array(self.clock_arrivals[:n])
        inside = (arrived >= since) & (arrived <= until)
        if inside.sum() < 2:
            return float("inf"), float("inf"), float("inf")
        sent = np.array(self.clock_sent[:n])[inside]
        bare = np.array(self.bare_clock_sent[:len(self.bare_clock_sent)])
        bare = bare[(bare >= sent[0]) & (bare <= sent[-1])]
        bare_gap = float(np.max(np.diff(bare))) if len(bare) > 1 else float("inf")
        return float(np.max(np.diff(sent))), float(np.max(np.diff(arrived[inside]))), bare_gap

    def stop_taken(self, service: str, since: float, until: float) -> float | None:
        """When the job took the stop request it answered at `until` (wall), asked after
        `since`: only this bench's main client calls stop."""
        taken = [t for t in self.stops_taken[service] if since - 0.05 <= t <= until]
        return taken[-1] if taken else None

    def control_period(self) -> float:
        return float(np.median(np.diff(np.array(self.clock_values[-500:]))))

    def close(self) -> None:
        self.executor.shutdown()
        self.node.destroy_node()


@dataclass
class Device:
    name: str
    path: str
    wait_action: type
    decel_s: float
    start: Callable[[RosClient, int], int | None]  # a motion that runs seconds: its id (or None)
    stop_srv: type
    fill: Callable[[RosClient, int], Any]          # one more queued move
    at_rest: Callable[[RosClient], bool]


def arm_start(ros: RosClient, trial: int) -> int | None:
    r = ros.call(srv.MovePTPJointRel, ARM + "move_ptp_joint_rel",
                 joint_points=[30.0 if trial % 2 else -30.0] + [0.0] * 6)
    return r.motion_id if r.return_id.id == 0 else None


def ahead(ros: RosClient, forward: float, left: float = 0.0) -> VehiclePoint:
    """A point `forward` mm ahead of the base and `left` mm to its left."""
    pos = ros.call(srv.VehicleGetPosition, BASE + "get_position").pos
    c, s = math.cos(math.radians(pos.theta)), math.sin(math.radians(pos.theta))
    return VehiclePoint(x=pos.x + forward * c - left * s, y=pos.y + forward * s + left * c)


def base_start(ros: RosClient, trial: int) -> int | None:
    """A cruise 1.5 m ahead (the base takes a move only when Ready; cruise points add up)."""
    r = ros.call(srv.VehicleMoveCruiseAbs, BASE + "move_cruise_abs",
                 cruise_point=ahead(ros, 1500.0))
    return r.motion_id if r.success else None


DEVICES = [
    Device("arm", ARM, WaitMotion, ARM_DECEL_S, arm_start, srv.Stop,
           lambda ros, i: ros.call(srv.MovePTPJointRel, ARM + "move_ptp_joint_rel",
                                   joint_points=[1.0 if i % 2 else -1.0] * 7),
           lambda ros: not ros.call(srv.GetState, ARM + "get_state").state & 0x02),
    Device("base", BASE, VehicleWaitMotion, BASE_DECEL_S, base_start, srv.VehicleStop,
           lambda ros, i: ros.call(srv.VehicleMoveCruiseAbs, BASE + "move_cruise_abs",
                                   cruise_point=ahead(ros, 1600.0 + 100.0 * i)),
           lambda ros: ros.call(srv.VehicleGetState, BASE + "get_state").state == 0x010),
]


def prepare(ros: RosClient) -> None:
    ros.call(srv.ServoON, ARM + "servo_on")
    ros.call(srv.SetSpeedJoint, ARM + "set_speed_joint", spd_ratio=30)
    ros.call(srv.SetSpeedCartesian, ARM + "set_speed_cartesian", spd_ratio=30)
    ros.call(srv.SetAccelTimeJoint, ARM + "set_accel_time_joint", acl_time=ARM_DECEL_S)
    ros.call(srv.VehicleSetPower, BASE + "set_power", on_off=True)
    ros.call(srv.VehicleSetServo, BASE + "set_servo", on_off=True)


def long_plan(ros: RosClient, bg: Background, device: Device, trial: int) -> Any:
    """A request that plans for long: an 800 mm line for the arm, one more cruise point 3 m away
    for the base (each plans from the end of the queue, sent by the background client)."""
    if device.name == "arm":
        m = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 800.0 if trial % 2 else -800.0,
             0.0, 0.0, 1.0, 0.0]
        return bg.send(srv.MoveLinearCartesianRel, ARM + "move_linear_cartesian_rel",
                       car_point=CarPosWithElbow(car_pos=m))
    return bg.send(srv.VehicleMoveCruiseAbs, BASE + "move_cruise_abs",
                   cruise_point=ahead(ros, 3000.0, 1000.0 if trial % 2 else -1000.0))


@dataclass
class Figures:
    reply: list[float]
    bare: list[float]
    rest: list[float]    # stop called → the wait's result here
    rest_job: list[float]    # stop called → the job said the wait ended (status source stamp)
    rest_answered: list[float]   # the job answered stop → it said the wait ended (both stamps)
    in_job: list[float]  # the job took stop → it answered (its service event, its response)
    clock_gap: float     # the job's largest /clock silence (source timestamps)
    clock_arrival_gap: float     # ... as seen by this client
    bare_clock_gap: float        # the bare publisher's largest silence meanwhile
    lost: list[str]      # the step each lost trial timed out in


Load = Callable[[Device, int, int], Any]      # (device, trial, its motion id) → what it holds


def started(ros: RosClient, device: Device, trial: int) -> int:
    """The trial's motion id, once accepted (a storm may have filled the queue: stop, retry)."""
    for _ in range(100):
        motion_id = device.start(ros, trial)
        if motion_id is not None:
            return motion_id
        ros.call(device.stop_srv, device.path + "stop")
        ros.spin_until(lambda: device.at_rest(ros), 10.0)
    raise RuntimeError(f"{device.name}: no motion accepted in 100 tries")


def running_motion(ros: RosClient, device: Device, waiter: Actions,
                   trial: int) -> tuple[int, Any, Any]:
    """The trial's motion, once it runs, and the goal handle and result of a wait on it. A move sent while the
    device decelerates from a stop is accepted and then discarded with the rest of the queue
    (spec 5.4.19): under a storm the previous trial's last stop can still be decelerating, so a
    motion that ends before it ran is started again."""
    for _ in range(20):
        motion_id = started(ros, device, trial)
        current: list[int] = []
        goal = waiter.send(lambda f: current.append(f.feedback.current_motion_id),
                           motion_id=motion_id, timeout=30.0)
        result = goal.get_result_async()
        if not ros.spin_until(lambda: motion_id in current or result.done(), 30.0):
            raise TimeoutError("the motion neither ran nor ended")
        if motion_id in current:
            return motion_id, goal, result
    raise TimeoutError("every motion was discarded before it ran")


def run_trials(ros: RosClient, bg: Background, device: Device, load: Load,
               waiter: Actions, trials: int) -> Figures:
    f = Figures([], [], [], [], [], [], 0.0, 0.0, 0.0, [])
    for trial in range(-1, trials):                     # trial -1 warms up (lazy imports)
        if trial == 0:
            f, t0 = Figures([], [], [], [], [], [], 0.0, 0.0, 0.0, []), time.monotonic()
        try:
            trial_figures(ros, bg, device, load, waiter, trial, f)
        except TimeoutError as e:
            f.lost.append(str(e))
            print(f"  {device.name} trial {trial}: {e}", file=sys.stderr, flush=True)
            ros.call(device.stop_srv, device.path + "stop")
    f.clock_gap, f.clock_arrival_gap, f.bare_clock_gap = bg.largest_clock_gaps(
        t0, time.monotonic())
    return f


def trial_figures(ros: RosClient, bg: Background, device: Device, load: Load, waiter: Actions,
                  trial: int, f: Figures) -> None:
    """One trial: start, load, bare call, stop, rest; the figures appended."""
    bare = bare_call(ros)
    motion_id, goal, result = running_motion(ros, device, waiter, trial)
    held = load(device, trial, motion_id)
    t = time.perf_counter()
    bare()
    f.bare.append(time.perf_counter() - t)
    wall, t = time.time(), time.perf_counter()
    answer = ros.call(device.stop_srv, device.path + "stop")
    f.reply.append(time.perf_counter() - t)
    answered = ANSWER_STAMPS.pop(id(answer), None)
    if not ros.wait(result, 30.0):
        raise TimeoutError("the stopped motion never retired")
    f.rest.append(time.perf_counter() - t)
    uuid = bytes(goal.goal_id.uuid)
    if not ros.spin_until(lambda: uuid in bg.goal_ended, 5.0):
        raise TimeoutError("no goal status said the wait ended")
    f.rest_job.append(bg.goal_ended[uuid] - wall)
    if answered is not None:
        f.rest_answered.append(bg.goal_ended[uuid] - answered)
        service = device.path + "stop"
        if ros.spin_until(lambda: bg.stop_taken(service, wall, answered) is not None, 5.0):
            f.in_job.append(answered - bg.stop_taken(service, wall, answered))
    ros.call(device.stop_srv, device.path + "stop")     # what a load queued meanwhile
    if isinstance(held, list):
        for future in held:                              # held goals end with the motion
            ros.wait(future, 30.0)


# counts to 2e9 inside a function (branches act only in one): computation without a motion,
# ~1.6 M instructions/s on the arm's program thread, each under the GIL, for ~20 minutes
BUSY_PROGRAM = """
.name i %1000
.name count %1001
VAR #i #count DCL
#i I4:0 STORE
#count FDEF Fn{
top:
  #i i INC STORE
  i I4:2000000000 LT >top BRT
  END
}
count
"""


@contextmanager
def busy_program(ros: RosClient) -> Iterator[None]:
    """A STROLIC program running on the arm for the whole case; canceled at its end."""
    programs = Actions(ros, RunProgram, ARM + "run_program")
    handle = programs.send(text=BUSY_PROGRAM)
    try:
        ros.spin_until(lambda: False, 1.0)      # the program runs
        yield
    finally:
        programs.cancel(handle)


@contextmanager
def storm(seconds: float) -> Iterator[None]:
    procs = [subprocess.Popen([sys.executable, os.path.abspath(__file__), "--storm",
                               str(seconds)], stdout=subprocess.DEVNULL)
             for _ in range(STORM_CLIENTS)]
    try:
        time.sleep(5.0)                     # the storm clients found the nodes and run
        yield
    finally:
        for proc in procs:
            proc.terminate()
            proc.wait(timeout=30)


@contextmanager
def busy_processes(count: int) -> Iterator[None]:
    """`count` processes that only compute, at the job's niceness (as other jobs on the
    machine, say a test suite's, run): what the job's threads compete with on equal terms."""
    procs = [subprocess.Popen([sys.executable, "-c",
                               f"import os; os.nice({NICENESS}); exec('while True: pass')"])
             for _ in range(count)]
    try:
        time.sleep(1.0)
        yield
    finally:
        for proc in procs:
            proc.terminate()
            proc.wait(timeout=30)


def storm_client(seconds: float) -> None:
    """One storm client: getters of both nodes and small moves, as fast as it can, until
    `seconds` pass or SIGTERM comes."""
    init(sys.argv)
    ros = RosClient(f"bench_storm_{os.getpid()}", call_timeout=5.0)
    calls = [lambda: ros.call(srv.GetState, ARM + "get_state"),
             lambda: ros.call(srv.GetFeedbackPosJoint, ARM + "get_feedback_pos_joint"),
             lambda: ros.call(srv.VehicleGetPosition, BASE + "get_position"),
             lambda: ros.call(srv.MovePTPJointRel, ARM + "move_ptp_joint_rel",
                              joint_points=[0.2] * 7),
             lambda: ros.call(srv.MovePTPJointRel, ARM + "move_ptp_joint_rel",
                              joint_points=[-0.2] * 7),
             lambda: ros.call(srv.VehicleMoveTurn, BASE + "move_turn", theta=0.5),
             lambda: ros.call(srv.VehicleMoveTurn, BASE + "move_turn", theta=-0.5)]
    end = time.monotonic() + seconds
    i = 0
    while time.monotonic() < end and not stop_requested():
        try:
            calls[i % len(calls)]()
        except TimeoutError:                # a storm goes on (a lost call is DDS's, not ours)
            pass
        i += 1
    ros.close()
    rclpy.try_shutdown()


def scenarios(ros: RosClient, bg: Background,
              waiters: dict[str, Actions]) -> dict[str, tuple[Load, Callable[[], Any]]]:
    """name → (per-trial load, context around the whole case)."""
    def planning(device: Device, trial: int, _motion_id: int) -> Any:
        future = long_plan(ros, bg, device, trial)
        time.sleep(0.003)                   # the plan is under way when stop is called
        return future

    def full_queue(device: Device, _trial: int, _motion_id: int) -> None:
        for i in range(QUEUE):
            device.fill(ros, i)

    def most_goals(device: Device, _trial: int, motion_id: int) -> list:
        """All the slots but the trial's own wait, on the trial's motion: the results."""
        return [waiters[device.name].send(motion_id=motion_id, timeout=60.0).get_result_async()
                for _ in range(MAX_GOALS - 1)]

    def nothing(_device: Device, _trial: int, _motion_id: int) -> None:
        return None

    return {
        "(a) a long move being planned": (planning, nullcontext),
        "(b) the queue full": (full_queue, nullcontext),
        "(c) the most action goals held": (most_goals, nullcontext),
        "(d) 8 clients storm getters and moves": (nothing, lambda: storm(seconds=600.0)),
        "(e) a STROLIC program computes": (nothing, lambda: busy_program(ros)),
        f"(f) {BUSY_PROCESSES} busy processes at niceness {NICENESS}":
            (nothing, lambda: busy_processes(BUSY_PROCESSES)),
    }


def udp_receive_drops() -> int:
    """UDP datagrams this machine's kernel dropped so far because a socket's receive buffer was
    full (`RcvbufErrors`): a reliable DDS writer sends such a sample again only after its next
    heartbeat, seconds later, which is how a storm loses calls."""
    with open("/proc/net/snmp") as f:
        names, values = [line.split()[1:] for line in f if line.startswith("Udp:")][:2]
    return int(values[names.index("RcvbufErrors")])


def lost_text(lost: list[str], dropped: int) -> str:
    """How many trials lost a call, and in which step; UDP datagrams dropped meanwhile."""
    drops = f"  {dropped} UDP datagrams dropped at full receive buffers" if dropped else ""
    if not lost:
        return drops
    return f"  {len(lost)} trials lost a call: " + "; ".join(
        f"{lost.count(why)}x {why}" for why in dict.fromkeys(lost)) + drops


def main(cases: str, trials: int = TRIALS) -> None:
    """`cases`: the letters of the cases to run (all when empty); `trials` per case and device."""
    record_answer_stamps()
    ros = RosClient(call_timeout=5.0)
    # /clock on every control step (clock_rate_hz = rate_hz), so its gaps show every stall
    params = (f"max_action_goals:={MAX_GOALS}", f"max_wait_goals:={MAX_GOALS}",
              f"queue_size:={QUEUE}", "rate_hz:=250.0", "clock_rate_hz:=250.0",
              # the control loop under SCHED_FIFO (opt-in): without it the base's planning held
              # /clock back 9-14 ms in cases (a)-(c)
              f"control_fifo_priority:={FIFO_PRIORITY}")
    with running("bench.trigger_server"), running("bench.clock_floor"), \
            running("acti_bringup", *params):
        bg = Background()
        bare_trigger_answers(ros)
        prepare(ros)
        assert ros.spin_until(lambda: len(bg.clock_values) > 100, 30.0), "no /clock"
        period = bg.control_period()
        print(f"stop under load, main job, {trials} trials per case; control period "
              f"{period * 1e3:.2f} ms (from /clock); times in ms")
        print(f"{'case':<40} {'dev':<5} {'bare p50/p99':>15} {'stop reply p50/p99/max':>25} "
              f"{'ratio p99':>9} {'in job p50/p99/max':>22} {'rest p50/p99/max':>25} {'goal':>7} "
              f"{'answered→p99':>12} {'received p99':>12} {'/clock gap':>10}")
        # one action client per device for the whole run: each new one would add entities to
        # both processes (and receivers of every goal status) for the rest of the run
        waiters = {d.name: Actions(ros, d.wait_action, d.path + "wait_motion") for d in DEVICES}
        for name, (load, context) in scenarios(ros, bg, waiters).items():
            if cases and name[1] not in cases:
                continue
            with context():
                for device in DEVICES:
                    drops = udp_receive_drops()
                    f = run_trials(ros, bg, device, load, waiters[device.name], trials)
                    drops = udp_receive_drops() - drops
                    reply, rest = np.array(f.reply), np.array(f.rest_job)
                    in_job = np.array(f.in_job or [np.nan])
                    goal = device.decel_s + 2 * period
                    print(f"{name:<40} {device.name:<5} {p(np.array(f.bare), 50):7.2f}/"
                          f"{p(np.array(f.bare), 99):7.2f} {p(reply, 50):7.2f}/{p(reply, 99):7.2f}/"
                          f"{reply.max() * 1e3:8.2f} {p(reply, 99) / p(np.array(f.bare), 99):9.2f}"
                          f" {p(in_job, 50):6.2f}/{p(in_job, 99):6.2f}/{np.max(in_job) * 1e3:7.2f}"
                          f" {p(rest, 50):7.1f}/{p(rest, 99):7.1f}/{rest.max() * 1e3:7.1f}"
                          f" {goal * 1e3:7.1f} {p(np.array(f.rest_answered or [np.nan]), 99):12.1f}"
                          f" {p(np.array(f.rest), 99):12.1f}"
                          f" {f.clock_gap * 1e3:7.1f} "
                          f"({f.clock_gap / period:.1f} periods; {f.clock_arrival_gap * 1e3:.1f}"
                          f" as it arrived; bare {f.bare_clock_gap * 1e3:.1f})"
                          + lost_text(f.lost, drops))
        bg.close()
    ros.close()


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "--storm":
        storm_client(float(sys.argv[2]))
    else:
        def option(name: str, default: str) -> str:
            return sys.argv[sys.argv.index(name) + 1] if name in sys.argv else default
        main(option("--cases", ""), int(option("--trials", str(TRIALS))))
