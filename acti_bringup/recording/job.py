"""What a job does for recording: its services and actions introspected (so that a recorder
keeps every call), and, when the `record` parameter names a file, a recorder started with the
job (`python -m acti_bringup.record`, a process of its own: writing costs the job's threads
nothing) and stopped with it, which closes the file."""
from __future__ import annotations

import os
import signal
import subprocess
import sys
from dataclasses import dataclass
from typing import Iterable

from rclpy.node import Node

from acti_bringup.harness import _end_with_parent, wait_until
from acti_bringup.recording.introspection import STATES, introspect
from acti_bringup.serving.parameters import declare_config

RECORDER_STOP_S = 10.0
RECORDER_READY_S = 30.0
RECORDER_NICE = 0


@dataclass
class RecordingConfig:
    # requests and answers of every service and action of the job on <service>/_service_event
    # topics, which a recording keeps: contents, metadata (who called when) or disabled
    service_introspection: str = "contents"
    # record everything (every topic, service call and action) from start-up into this MCAP
    # file, closed when the job ends (python -m acti_bringup.record); "": no recording
    record: str = ""


def _recorder_process() -> None:
    """In the recorder's process: ends with the job, and runs at ordinary niceness or lower,
    behind the job's threads (the job's `nice` lowers theirs, -10 by default; raising a
    niceness needs no privilege)."""
    _end_with_parent()
    os.setpriority(os.PRIO_PROCESS, 0, max(os.getpriority(os.PRIO_PROCESS, 0), RECORDER_NICE))


class JobRecording:
    """The recording settings of the node that hosts the process's simulation."""

    def __init__(self, node: Node) -> None:
        self.config = c = declare_config(node, RecordingConfig)
        if c.service_introspection not in STATES:
            raise ValueError(f"service_introspection is {c.service_introspection!r}: use one of "
                             + ", ".join(STATES))
        self._log = node.get_logger()
        self._recorder: subprocess.Popen | None = None
        if c.record:
            self._recorder = subprocess.Popen(
                [sys.executable, "-m", "acti_bringup.record", c.record, "--ros-args",
                 "-r", f"__ns:={node.get_namespace()}"], preexec_fn=_recorder_process)
            self._log.info(f"recording to {c.record} (the recorder's process: "
                           f"{self._recorder.pid})")

    def introspect(self, nodes: Iterable[Node]) -> None:
        """Once the nodes serve with their final action handles (`Simulation.spin`), before
        they answer anything. With a recorder: until it subscribed to every service event topic
        (at most RECORDER_READY_S), so that the recording holds the first call too."""
        nodes = list(nodes)
        topics = introspect(nodes, self.config.service_introspection)
        if self._recorder is None or not nodes:
            return
        graph = nodes[0]
        if not wait_until(lambda: all(graph.count_subscribers(t) for t in topics),
                          RECORDER_READY_S):
            missed = [t for t in topics if not graph.count_subscribers(t)]
            self._log.warning(f"the recorder has not subscribed to {len(missed)} service event "
                              f"topics after {RECORDER_READY_S:g} s (first: {missed[0]}): their "
                              "first calls may be missing from the recording")

    def stop(self) -> None:
        """End the recorder (SIGINT: it closes the file)."""
        recorder = self._recorder
        if recorder is None or recorder.poll() is not None:
            return
        recorder.send_signal(signal.SIGINT)
        try:
            recorder.wait(timeout=RECORDER_STOP_S)
        except subprocess.TimeoutExpired:
            self._log.error(f"the recorder did not end in {RECORDER_STOP_S} s: killed, "
                            f"{self.config.record} may lack its last chunk")
            recorder.kill()
            recorder.wait()
