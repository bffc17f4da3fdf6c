"""Start the real nodes as processes and call them over DDS: used by the integration tests and
the benchmarks alike."""
from __future__ import annotations

import ctypes
import os
import signal
import subprocess
import sys
import time
from typing import Any, Callable

from acti_msgs import srv
from acti_msgs.msg import VehiclePoint, VehicleVelocity

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SERVICE_TIMEOUT = 30.0
CALL_TIMEOUT = 30.0
ACTION_TIMEOUT = 60.0


PR_SET_PDEATHSIG = 1


def _end_with_parent() -> None:
    """In the child: SIGTERM it when the process that started it dies, however it dies (a crash
    of a test or bench process leaves no node running behind it)."""
    ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGTERM)


class NodeProcess:
    """`python -m <module> [args] --ros-args -p <params>` (and a namespace for one robot of a
    fleet, a parameter file); stopped by PID (SIGINT, then SIGKILL)."""

    def __init__(self, module: str, log_path: str, *params: str, args: tuple[str, ...] = (),
                 namespace: str = "", params_file: str | tuple[str, ...] = "") -> None:
        command = [sys.executable, "-m", module, *args, "--ros-args"]
        if namespace:
            command += ["-r", f"__ns:={namespace}"]
        for path in [params_file] if isinstance(params_file, str) else params_file:
            command += ["--params-file", path] if path else []
        for p in params:
            command += ["-p", p]
        self.log_path = log_path
        self._log = open(log_path, "w")
        self.proc = subprocess.Popen(command, cwd=ROOT, stdout=self._log, stderr=subprocess.STDOUT,
                                     preexec_fn=_end_with_parent)

    def alive(self) -> bool:
        return self.proc.poll() is None

    def log(self) -> str:
        with open(self.log_path) as f:
            return f.read()

    def stop(self) -> int:
        if self.alive():
            self.proc.send_signal(signal.SIGINT)
            try:
                self.proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(timeout=10)
        self._log.close()
        return self.proc.returncode


class RosClient:
    """One rclpy node in the test process that calls services and waits for conditions.

    It waits by `spin_once` in a loop of its own: rclpy's `spin_until_future_complete` on a
    long-lived executor gets slower with every call (2 ms to 30 ms over 900 calls), which would
    make the benchmarks measure the client."""

    def __init__(self, name: str = "acti_test_client", call_timeout: float = CALL_TIMEOUT) -> None:
        """The first client of a process initialises rclpy (and shuts it down on close)."""
        import rclpy
        from rclpy.executors import SingleThreadedExecutor
        from acti_bringup.serving.adapter import CLIENT_QOS
        self.rclpy = rclpy
        self.client_qos = CLIENT_QOS      # a busy client keeps its answer among others' (adapter)
        self._owns_context = not rclpy.ok()
        if self._owns_context:
            rclpy.init()
        self.node = rclpy.create_node(name)
        self.call_timeout = call_timeout
        self.executor = SingleThreadedExecutor()
        self.executor.add_node(self.node)
        self._clients: dict[str, Any] = {}

    def call(self, srv_type: type, name: str, **fields: Any) -> Any:
        client = self._clients.get(name)
        if client is None:
            client = self._clients[name] = self.node.create_client(srv_type, name,
                                                                   qos_profile=self.client_qos)
        # also after the server's process was restarted (the next test module's node)
        if not client.service_is_ready() and not client.wait_for_service(timeout_sec=SERVICE_TIMEOUT):
            raise TimeoutError(f"service {name} did not appear")
        future = client.call_async(srv_type.Request(**fields))
        if not self.wait(future, self.call_timeout):
            raise TimeoutError(f"{name} did not answer in {self.call_timeout} s")
        return future.result()

    def wait(self, future: Any, timeout: float) -> bool:
        """Serve this client until `future` is done; False after `timeout` seconds."""
        return self.spin_until(future.done, timeout, period=min(timeout, 1.0))

    def spin_until(self, predicate: Callable[[], bool], timeout: float,
                   period: float = 0.02) -> bool:
        """Serve this client's subscriptions and callbacks until predicate() holds."""
        deadline = time.monotonic() + timeout
        while not predicate():
            left = deadline - time.monotonic()
            if left <= 0:
                return False
            self.executor.spin_once(timeout_sec=min(period, left))
        return True

    def close(self) -> None:
        self.executor.shutdown()
        self.node.destroy_node()
        if self._owns_context:
            self.rclpy.try_shutdown()


class Actions:
    """Goals of one action (its full name) over the test client's executor."""

    def __init__(self, ros: "RosClient", action_type: type, name: str) -> None:
        from rclpy.action import ActionClient
        from acti_bringup.serving.adapter import CLIENT_ACTION_QOS
        self.ros, self.type = ros, action_type
        self.client = ActionClient(ros.node, action_type, name, **CLIENT_ACTION_QOS)
        assert self.client.wait_for_server(timeout_sec=30.0)

    def spin(self, future: Any, timeout: float = ACTION_TIMEOUT) -> Any:
        assert self.ros.wait(future, timeout), "no answer in time"
        return future.result()

    def offer(self, feedback: Callable[[Any], None] | None = None, **fields: Any) -> Any:
        """The goal handle, accepted or not."""
        return self.spin(self.client.send_goal_async(self.type.Goal(**fields),
                                                     feedback_callback=feedback))

    def send(self, feedback: Callable[[Any], None] | None = None, **fields: Any) -> Any:
        handle = self.offer(feedback, **fields)
        assert handle.accepted
        return handle

    def result(self, handle: Any) -> tuple[int, Any]:
        out = self.spin(handle.get_result_async())
        return out.status, out.result

    def cancel(self, handle: Any) -> None:
        self.spin(handle.cancel_goal_async())


def wait_until(predicate: Callable[[], bool], timeout: float, period: float = 0.05) -> bool:
    """Poll until predicate() holds; False on timeout (never a fixed sleep)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(period)
    return False


# one `ros2 service call`: a DDS participant that starts, calls one service and ends
_ONE_CALL = """import importlib, sys, rclpy
module, name, service = sys.argv[1:4]
srv_type = getattr(importlib.import_module(module), name)
rclpy.init()
node = rclpy.create_node("one_call")
client = node.create_client(srv_type, service)
if client.wait_for_service(timeout_sec=20.0):
    rclpy.spin_until_future_complete(node, client.call_async(srv_type.Request()), timeout_sec=10.0)
"""


class OneShotClients:
    """Keep `count` one-shot client processes (`_ONE_CALL`: one call of `service`, of type
    `srv_type` whose request needs no field) running, a new one as soon as one ends, while
    `keep()` is called: DDS participants that come and go, as every `ros2` command is one."""

    def __init__(self, srv_type: type, service: str, count: int = 2) -> None:
        self.call = [srv_type.__module__.rsplit(".", 1)[0], srv_type.__name__, service]
        self.count, self.started = count, 0
        self._running: list[subprocess.Popen] = []

    def keep(self) -> None:
        self._running = [c for c in self._running if c.poll() is None]
        while len(self._running) < self.count:
            self._running.append(subprocess.Popen(
                [sys.executable, "-c", _ONE_CALL, *self.call],
                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, preexec_fn=_end_with_parent))
            self.started += 1

    def end(self) -> None:
        """Let the running ones finish (killed after 60 s)."""
        for c in self._running:
            try:
                c.wait(timeout=60.0)
            except subprocess.TimeoutExpired:
                c.kill()
        self._running = []


FELL_BEHIND = r"fell (\d+) ms behind"    # the control loop's report (MotionExecutor), in ms


# both devices kept moving, for the recording's tests and benches: slow motions, so that a
# queue lasts even as fast as the job can (25x)
ARM, BASE = "/acti_middle_node/", "/vehicle_node/"
POSES = ([30.0, 40.0, 20.0, -70.0, 20.0, 50.0, 10.0], [-30.0, 20.0, -20.0, -50.0, -20.0, 70.0, -10.0])
SQUARE = ((1000.0, 0.0), (1000.0, 1000.0), (0.0, 1000.0), (0.0, 0.0))   # mm
BASE_MOVING = 0x011                     # the base's state code while it moves


def start_moving(ros: RosClient) -> None:
    """Both devices powered and slow: the arm at 5 % joint speed, the base at 100 mm/s."""
    ros.call(srv.ServoON, ARM + "servo_on")
    ros.call(srv.SetSpeedJoint, ARM + "set_speed_joint", spd_ratio=5)
    ros.call(srv.VehicleSetPower, BASE + "set_power", on_off=True)
    ros.call(srv.VehicleSetServo, BASE + "set_servo", on_off=True)
    ros.call(srv.VehicleSetVelocity, BASE + "set_velocity",
             vel=VehicleVelocity(translation=100.0, rotation=5.0))


def keep_moving(ros: RosClient, motions: int) -> None:
    """`motions` queued on each device: the arm between two poses, the base round a square."""
    for i in range(motions):
        ros.call(srv.MovePTPJointAbs, ARM + "move_ptp_joint_abs", joint_points=POSES[i % 2])
        x, y = SQUARE[i % len(SQUARE)]
        reply = ros.call(srv.VehicleMoveCruiseAbs, BASE + "move_cruise_abs",
                         cruise_point=VehiclePoint(x=x, y=y))
        assert reply.success, reply.message


def both_moving(ros: RosClient) -> bool:
    return bool(ros.call(srv.GetState, ARM + "get_state").state & 0x2) and \
        ros.call(srv.VehicleGetState, BASE + "get_state").state == BASE_MOVING


def stop_moving(ros: RosClient) -> None:
    ros.call(srv.Stop, ARM + "stop")
    ros.call(srv.VehicleStop, BASE + "stop")
