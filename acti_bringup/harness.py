"""Start the real nodes as processes and call them over DDS: used by the integration tests and
the benchmarks alike."""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from typing import Any, Callable

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SERVICE_TIMEOUT = 30.0
CALL_TIMEOUT = 30.0


class NodeProcess:
    """`python -m <module>` with --ros-args (parameters `name:=value`, and a namespace for one
    robot of a fleet); stopped by PID (SIGINT, then SIGKILL)."""

    def __init__(self, module: str, log_path: str, *params: str, namespace: str = "") -> None:
        args = [sys.executable, "-m", module, "--ros-args"]
        if namespace:
            args += ["-r", f"__ns:={namespace}"]
        for p in params:
            args += ["-p", p]
        self.log_path = log_path
        self._log = open(log_path, "w")
        self.proc = subprocess.Popen(args, cwd=ROOT, stdout=self._log, stderr=subprocess.STDOUT)

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
    """One rclpy node in the test process that calls services and waits for conditions."""

    def __init__(self) -> None:
        import rclpy
        from rclpy.executors import SingleThreadedExecutor
        self.rclpy = rclpy
        rclpy.init()
        self.node = rclpy.create_node("acti_test_client")
        self.executor = SingleThreadedExecutor()
        self.executor.add_node(self.node)
        self._clients: dict[str, Any] = {}

    def call(self, srv_type: type, name: str, **fields: Any) -> Any:
        client = self._clients.get(name)
        if client is None:
            client = self._clients[name] = self.node.create_client(srv_type, name)
        # also after the server's process was restarted (the next test module's node)
        if not client.service_is_ready() and not client.wait_for_service(timeout_sec=SERVICE_TIMEOUT):
            raise TimeoutError(f"service {name} did not appear")
        future = client.call_async(srv_type.Request(**fields))
        self.executor.spin_until_future_complete(future, timeout_sec=CALL_TIMEOUT)
        if not future.done():
            raise TimeoutError(f"{name} did not answer in {CALL_TIMEOUT} s")
        return future.result()

    def spin_until(self, predicate: Callable[[], bool], timeout: float) -> bool:
        """Serve this client's subscriptions and callbacks until predicate() holds."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if predicate():
                return True
            self.executor.spin_once(timeout_sec=0.02)
        return predicate()

    def close(self) -> None:
        self.executor.shutdown()
        self.node.destroy_node()
        self.rclpy.try_shutdown()


def wait_until(predicate: Callable[[], bool], timeout: float, period: float = 0.05) -> bool:
    """Poll until predicate() holds; False on timeout (never a fixed sleep)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(period)
    return False
