"""pytest fixtures over `acti_bringup.harness`: the client node and one node process per file."""
from __future__ import annotations

import signal

import pytest

from acti_bringup.harness import NodeProcess, RosClient, wait_until  # noqa: F401

TEST_RATE = "real_time_factor:=4.0"
ACTION_TIMEOUT = 60.0


@pytest.fixture(scope="session")
def ros() -> RosClient:
    client = RosClient()
    yield client
    client.close()


def node_fixture(module: str, *params: str):
    """A module-scoped fixture running one node process (4× real time) for the tests of a file."""
    @pytest.fixture(scope="module")
    def fixture(tmp_path_factory):
        log = str(tmp_path_factory.mktemp(module) / "node.log")
        node = NodeProcess(module, log, TEST_RATE, *params)
        yield node
        alive = node.alive()
        code = node.stop()
        assert alive, f"{module} died during the tests:\n{node.log()}"
        assert code in (0, -signal.SIGINT), f"{module} exited with {code}:\n{node.log()}"
        assert "Traceback" not in node.log(), f"{module} logged an exception:\n{node.log()}"
    return fixture


class Actions:
    """Goals of one action (its full name) over the test client's executor."""

    def __init__(self, ros: RosClient, action_type: type, name: str) -> None:
        from rclpy.action import ActionClient
        self.ros, self.type = ros, action_type
        self.client = ActionClient(ros.node, action_type, name)
        assert self.client.wait_for_server(timeout_sec=30.0)

    def spin(self, future, timeout: float = ACTION_TIMEOUT):
        assert self.ros.wait(future, timeout), "no answer in time"
        return future.result()

    def offer(self, feedback=None, **fields):
        """The goal handle, accepted or not."""
        return self.spin(self.client.send_goal_async(self.type.Goal(**fields),
                                                     feedback_callback=feedback))

    def send(self, feedback=None, **fields):
        handle = self.offer(feedback, **fields)
        assert handle.accepted
        return handle

    def result(self, handle):
        out = self.spin(handle.get_result_async())
        return out.status, out.result

    def cancel(self, handle) -> None:
        self.spin(handle.cancel_goal_async())
