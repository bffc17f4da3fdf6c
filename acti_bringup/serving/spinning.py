"""How a process serves its nodes: three planes, each on an executor and a thread of its own.

- The control plane (stop, pause, resume, servo, get_state, the getters and setters, parameters,
  the timers and topics) runs on rclpy's `EventsExecutor`: it keeps no wait set to rebuild on
  every wake (48 % of the GIL under a getter storm with the MultiThreadedExecutor), so a call
  costs about what a bare node's does. Nothing on it plans or waits.
- The motion plane (the services that plan a move, cmd_vel/joy) runs on an `EventsExecutor` of
  its own: planning for ms there never delays the control plane.
- The goal plane (the action servers) runs on a `SingleThreadedExecutor`: goals are coroutines
  that await (`acti_bringup.serving.waiting`), which the EventsExecutor would poll without pause.

What the planes and the control loop send (messages, the actions' feedback and answers, a new
client's responses) leaves through one outbox thread, without the GIL; a known client's response
leaves at once, without the GIL too (`acti_bringup.serving.outbox`, `responses`): a send that DDS
holds back holds no other thread and no control step.

Each executor is driven by a `spin_once` loop (the EventsExecutor's `spin()` serves nothing in
this rclpy and neither honours SIGINT); SIGINT and SIGTERM are handled here, on the main thread.
"""
from __future__ import annotations

import os
import signal
import sys
import threading
import time
from typing import Callable, Iterable, NoReturn, TypeVar

import rclpy
from rclpy.action import ActionServer
from rclpy.exceptions import InvalidParameterTypeException, InvalidParameterValueException
from rclpy.executors import Executor, SingleThreadedExecutor
from rclpy.impl.implementation_singleton import rclpy_implementation
from rclpy.signals import SignalHandlerOptions
from rclpy.experimental import EventsExecutor
from rclpy.logging import get_logger
from rclpy.clock import Clock, ClockType
from rclpy.node import Node
from rclpy.publisher import Publisher
from rclpy.timer import Timer

from acti_bringup.serving.logs import route_python_logging
from acti_bringup.serving.namesakes import DISCOVERY_WAIT_S, JobConfig, namesakes, refusal
from acti_bringup.serving.outbox import Outbox, unlock_action, unlocked_publish
from acti_bringup.serving.parameters import declare_config
from acti_bringup.serving.params_files import warn_of_unmatched_files
from acti_bringup.serving.responses import LateResponses
from acti_bringup.serving.usage import remember_parameters

RCLError = rclpy_implementation.RCLError
T = TypeVar("T")
SPIN_TIMEOUT_S = 0.5        # a loop's longest sleep: how soon it notices it should end
SIGNALS = (signal.SIGINT, signal.SIGTERM)
_stop_requested = threading.Event()


def catch_signals() -> None:
    """SIGINT/SIGTERM only set a flag that `wait_for_signal` watches: a signal while the nodes
    are still being built ends the process as cleanly as one while they serve."""
    for s in SIGNALS:
        signal.signal(s, lambda _signum, _frame: _stop_requested.set())


def stop_requested() -> bool:
    """SIGINT or SIGTERM came (after `catch_signals`)."""
    return _stop_requested.is_set()


_given_args: list[str] = []        # the process's arguments, as `init` got them
_init_at = [0.0]                   # when `init` ran (time.monotonic())
DISCOVERY_FROM_INIT_S = 6.0
MAX_DOMAIN_ID = 232     # Fast DDS: 7400 + 250 × domain + offsets must stay a UDP port


def init(args: list[str]) -> None:
    """rclpy.init with this module's signal handling instead of rclpy's. ROS arguments rcl
    refuses (a remap it cannot parse, a parameters file it cannot read) and a ROS_DOMAIN_ID
    DDS cannot use end the process as a refused setting does (`build_or_exit`). (`--help` is
    answered before: `acti_bringup.serving.usage`.)"""
    _given_args[:] = args
    _init_at[0] = time.monotonic()
    catch_signals()
    domain = os.environ.get("ROS_DOMAIN_ID", "").strip()
    if domain and not (domain.isdigit() and int(domain) <= MAX_DOMAIN_ID):
        _cannot_start(_program_name(), f"ROS_DOMAIN_ID={domain} is not a DDS domain: use 0 … "
                      f"{MAX_DOMAIN_ID} (DDS derives its UDP ports from it; 0 … 101 stay clear "
                      "of Linux's ephemeral ports)")
    try:
        rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    except RCLError as e:
        _cannot_start(_program_name(), e)


def _program_name() -> str:
    """What was started: `acti_bringup` for `python -m acti_bringup`, else the script's name."""
    spec = getattr(sys.modules["__main__"], "__spec__", None)
    if spec is not None:
        return spec.name.removesuffix(".__main__")
    return os.path.basename(sys.argv[0]) if sys.argv and sys.argv[0] else "python"


def _cannot_start(name: str, why: BaseException) -> NoReturn:
    """One FATAL line that says why, exit status 2."""
    get_logger(name).fatal(f"cannot start: {why}")
    rclpy.try_shutdown()
    raise SystemExit(2)


def build_or_exit(build: Callable[[], T], name: str, builder: str = "") -> T:
    """build() the process's nodes. A start-up setting they refuse (a parameter out of its range
    or of the wrong type, settings that contradict each other) ends the process with one line that
    says what, and exit status 2: a configuration error, not a traceback. What the cores log
    (Python's `logging`) goes through the first node's logger (`acti_bringup.serving.logs`).
    `builder` ("module:function" of `build`) names the list of parameters `--help` prints: kept
    now if it is not yet (`acti_bringup.serving.usage`)."""
    route_python_logging(get_logger(name))
    try:
        built = build()
        nodes = built if isinstance(built, tuple) else (built,)
        route_python_logging(nodes[0].get_logger())
        allowed = declare_job_parameters(nodes).allow_namesakes
        warn_of_unknown_parameters(nodes)
        warn_of_unmatched_files(nodes, _given_args, nodes[0].get_logger().warning)
        # discovery learns the other jobs' nodes over seconds from the start (longer on a busy
        # machine): look until DISCOVERY_FROM_INIT_S after init, and at least DISCOVERY_WAIT_S
        wait_s = max(DISCOVERY_WAIT_S, _init_at[0] + DISCOVERY_FROM_INIT_S - time.monotonic())
        taken = [] if allowed else namesakes(nodes, wait_s)
        if taken:
            _cannot_start(name, refusal(taken))
        if builder:
            remember_parameters(builder, nodes)
        return built
    except (ValueError, InvalidParameterTypeException, InvalidParameterValueException) as e:
        _cannot_start(name, e)
    except RCLError as e:       # a name clash: `-r __node:=x` renames every node of the process
        _cannot_start(name, f"{e} (do two nodes of the process have one name? `-r __node:=…` "
                            "renames every one of them; `-r vehicle_node:__node:=…` one)")


def declare_job_parameters(nodes: tuple[Node, ...]) -> JobConfig:
    """The parameters of the job as a whole, on its first node."""
    return declare_config(nodes[0], JobConfig)


def warn_of_unknown_parameters(nodes: tuple[Node, ...]) -> None:
    """Say which settings given (-p, --params-file) no node of the process has: most likely
    misspelt (`velocity_limit_translatoin`), and rclpy would ignore them without a word. A `-p`
    reaches every node of the process, so a name is unknown only when none of them has it."""
    known = {name for node in nodes for name in node._parameters}
    given = {name for node in nodes for name in getattr(node, "_parameter_overrides", {})}
    if given - known and nodes:
        nodes[0].get_logger().warning("unknown parameters, ignored (misspelt?): "
                                      + ", ".join(sorted(given - known)))


_STEADY = Clock(clock_type=ClockType.STEADY_TIME)


def steady_timer(node: Node, period: float, callback: Callable[[], None]) -> Timer:
    """A timer of the node's own cadence (state topics, action feedback) on the steady clock:
    on the node's clock it would stop whenever `use_sim_time` is set and no /clock comes
    (a node's `use_sim_time` can be set at run time), and with it the state topic, the
    settings mirrored into parameters and every waiting action goal."""
    return node.create_timer(period, callback, clock=_STEADY)


NAMESAKE_CHECK_S = 2.0


def warn_of_namesakes(node: Node, publisher: Publisher) -> Timer:
    """Log an error while another node publishes on `publisher`'s topic (its node's own
    `~/state`): a second job started in the same namespace, and clients' calls reach either
    one. Said once each time it starts, from the graph every NAMESAKE_CHECK_S; not a refusal to
    start, since the graph can still list a node that has just ended."""
    topic, seen = publisher.topic_name, 1

    def check() -> None:
        nonlocal seen
        count = node.count_publishers(topic)
        if count > 1 and seen <= 1:
            node.get_logger().error(
                f"{count} nodes publish {topic}: another job runs as "
                f"{node.get_fully_qualified_name()}, and clients reach either one (give each "
                "robot its own namespace: -r __ns:=/robotN)")
        seen = count
    return steady_timer(node, NAMESAKE_CHECK_S, check)


class SpinLoop:
    """One executor served by `spin_once` on a thread of its own until `stop()`."""

    def __init__(self, executor: Executor, name: str) -> None:
        self.executor, self.name = executor, name
        self.error: BaseException | None = None
        self._running = threading.Event()
        self._thread = threading.Thread(target=self._loop, name=name, daemon=True)

    def start(self) -> "SpinLoop":
        self._running.set()
        self._thread.start()
        return self

    @property
    def alive(self) -> bool:
        return self._thread.is_alive()

    def _loop(self) -> None:
        context = self.executor.context
        try:
            while self._running.is_set() and context.ok():
                self.executor.spin_once(timeout_sec=SPIN_TIMEOUT_S)
        except BaseException as e:  # ends the process's serving: the main thread reports it
            if context.ok() and self._running.is_set():
                self.error = e

    def stop(self) -> None:
        self._running.clear()
        self.executor.wake()
        self._thread.join(timeout=5.0)


class Planes:
    """The executors of one process, one per plane, and their loops."""

    KINDS: dict[str, Callable[[], Executor]] = {
        "control": EventsExecutor, "motion": EventsExecutor, "goals": SingleThreadedExecutor}

    def __init__(self) -> None:
        self.executors = {plane: kind() for plane, kind in self.KINDS.items()}
        self._loops: list[SpinLoop] = []
        self.outbox = Outbox(get_logger("acti_outbox").warning)
        self._late = LateResponses(get_logger("acti_responses").warning, self.outbox)

    def add(self, plane: str, nodes: Iterable[Node]) -> None:
        """Serve the nodes on the plane. What they send leaves through the outbox; a response
        DDS cannot deliver yet is sent again."""
        nodes = list(nodes)
        for n in nodes:
            self.executors[plane].add_node(n)
            for publisher in n.publishers:
                publisher.publish = unlocked_publish(self.outbox, publisher)
            for waitable in n.waitables:
                if isinstance(waitable, ActionServer):
                    unlock_action(waitable, self.outbox)
        self._late.serve(nodes)

    def start(self) -> None:
        self._loops = [SpinLoop(ex, f"ros-{plane}").start() for plane, ex in self.executors.items()]

    def serving(self) -> bool:
        return all(loop.alive for loop in self._loops)

    def errors(self) -> list[BaseException]:
        return [loop.error for loop in self._loops if loop.error is not None]

    def stop(self) -> None:
        for loop in self._loops:
            loop.stop()
        for ex in self.executors.values():
            ex.shutdown(timeout_sec=5.0)
        self.outbox.stop()


def wait_for_signal(still_serving: Callable[[], bool]) -> None:
    """Block the main thread until SIGINT/SIGTERM (or until `still_serving()` says no).

    The handlers are installed again: each EventsExecutor puts in its own when created.
    """
    catch_signals()
    while not _stop_requested.wait(SPIN_TIMEOUT_S):
        if not (still_serving() and rclpy.ok()):
            return
