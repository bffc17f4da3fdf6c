"""A job refuses to start where its nodes' names are already served in its ROS domain: two
jobs would answer the same services (two simulations, one robot's name), and a client would
reach either. `-p allow_namesakes:=true` starts it all the same (the graph can list for a while
the nodes of a job that was killed); `warn_of_namesakes` (spinning) still says so at run time."""
from __future__ import annotations

import os
import time
from dataclasses import dataclass

from rclpy.node import Node

DISCOVERY_WAIT_S = 1.0      # how long a start looks for a namesake (one appears in ~0.1 s)


@dataclass
class JobConfig:
    # start even where a node of this job's name is already served in the ROS domain (then
    # both jobs answer its services); for a job killed a moment ago, whose nodes the graph
    # still lists for a while
    allow_namesakes: bool = False


def namesakes(nodes: tuple[Node, ...], wait_s: float = DISCOVERY_WAIT_S) -> list[str]:
    """The full names of `nodes` another node of the domain has too, as far as discovery finds
    within wait_s (it stops looking once it has found them all)."""
    own = [n.get_fully_qualified_name() for n in nodes if not n.get_name().startswith("_")]
    deadline = time.monotonic() + wait_s
    while True:
        graph = [ns.rstrip("/") + "/" + name for name, ns in nodes[0].get_node_names_and_namespaces()]
        taken = [name for name in own if graph.count(name) > 1]
        if len(taken) == len(own) or time.monotonic() >= deadline:
            return taken
        time.sleep(0.05)


def refusal(taken: list[str]) -> str:
    """The one line that says which names and how to fix it."""
    domain = os.environ.get("ROS_DOMAIN_ID", "0") or "0"
    return (f"{', '.join(taken)} already served in ROS_DOMAIN_ID={domain} (another job runs): "
            "stop it, or start this one in a namespace of its own (--ros-args -r __ns:=/robotN) "
            "or another domain (export ROS_DOMAIN_ID=N); -p allow_namesakes:=true starts it "
            "all the same")
