"""pytest fixtures over `acti_bringup.harness`: the client node and one node process per file."""
from __future__ import annotations

import signal

import pytest
from rclpy.experimental import EventsExecutor

from acti_bringup.harness import Actions, NodeProcess, RosClient, wait_until  # noqa: F401
from acti_bringup.serving.spinning import SpinLoop

TEST_RATE = "real_time_factor:=4.0"


@pytest.fixture(scope="session")
def ros() -> RosClient:
    client = RosClient()
    yield client
    client.close()


def node_fixture(module: str, *params: str, namespace: str = "", params_yaml: str = ""):
    """A module-scoped fixture running one node process (4× real time) for the tests of a file,
    in `namespace` when given (one robot of a fleet), with a parameter file of `params_yaml`."""
    @pytest.fixture(scope="module")
    def fixture(tmp_path_factory):
        folder = tmp_path_factory.mktemp(module)
        params_file = ""
        if params_yaml:
            params_file = str(folder / "params.yaml")
            with open(params_file, "w") as f:
                f.write(params_yaml)
        node = NodeProcess(module, str(folder / "node.log"), TEST_RATE, *params,
                           namespace=namespace, params_file=params_file)
        yield node
        alive = node.alive()
        code = node.stop()
        assert alive, f"{module} died during the tests:\n{node.log()}"
        assert code in (0, -signal.SIGINT), f"{module} exited with {code}:\n{node.log()}"
        assert "Traceback" not in node.log(), f"{module} logged an exception:\n{node.log()}"
    return fixture


@pytest.fixture
def events_loop(ros):
    """A node on an EventsExecutor driven by a SpinLoop; the process's signal handlers are put
    back afterwards (the EventsExecutor installs its own)."""
    saved = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    node = ros.rclpy.create_node("spin_loop_test")
    executor = EventsExecutor()
    executor.add_node(node)
    loop = SpinLoop(executor, "test-events")
    yield node, loop
    loop.stop()
    executor.shutdown()
    node.destroy_node()
    for s, handler in saved.items():
        signal.signal(s, handler)
