"""Baselines for the round-trip benchmarks: bare servers, nothing behind them.

Served the way the nodes serve their control plane (`acti_bringup.serving.spinning`: an EventsExecutor
driven by a spin_once loop), so the ratio measures the nodes' own cost, not an executor choice:

    python -m bench.trigger_server [events|single|multi]   a std_srvs/Trigger, /bare_trigger/trigger
    python -m bench.trigger_server follow                  a control_msgs FollowJointTrajectory,
                                                           /bare_follow/follow_joint_trajectory, on the
                                                           goal plane's executor (single): it accepts
                                                           every goal and succeeds at once
    python -m bench.trigger_server replay [--nice=N] [SERVICE ...]
                                                           the services named (default: every getter
                                                           of both nodes) as /bare_replay/<node>/<op>:
                                                           a getter answers the reply the running main
                                                           job gave it once, any other operation an
                                                           OK reply (motion id 1) and does nothing;
                                                           served as the job serves them: the same
                                                           QoS (SERVICE_QOS) and introspection (the
                                                           job's default `service_introspection`);
                                                           with --nice, its threads at that niceness
                                                           (the job's: what a bare node deployed as
                                                           the job is costs)

The replay server tells a call's cost over a bare node answering the same messages (what the
ROS layer and, for a move, its plan cost) apart from its cost over a Trigger (which adds the
larger messages' own conversions at both ends)."""
import sys

import rclpy
from rclpy.executors import MultiThreadedExecutor, SingleThreadedExecutor
from rclpy.experimental import EventsExecutor
from std_srvs.srv import Trigger

from acti_bringup.priority import set_niceness
from acti_bringup.serving.spinning import SpinLoop, init, wait_for_signal
from acti_middle_node.operations import OPERATIONS as ARM_OPERATIONS
from vehicle_node.operations import OPERATIONS as BASE_OPERATIONS

EXECUTORS = {"events": EventsExecutor, "single": SingleThreadedExecutor,
             "multi": MultiThreadedExecutor}
KIND = "events"
REPLAY = "/bare_replay"
SERVICES = {f"/{node}/{op.name}": op.srv_type
            for node, ops in (("acti_middle_node", ARM_OPERATIONS), ("vehicle_node", BASE_OPERATIONS))
            for op in ops}
GETTERS = [(name, srv_type) for name, srv_type in SERVICES.items()
           if name.rsplit("/", 1)[1].startswith("get_")]


def trigger_node() -> rclpy.node.Node:
    node = rclpy.create_node("bare_trigger")

    def answer(_req, resp):
        resp.success = True
        return resp
    node.create_service(Trigger, "~/trigger", answer)
    return node


def follow_node() -> rclpy.node.Node:
    """A FollowJointTrajectory server that accepts every goal and succeeds at once."""
    from control_msgs.action import FollowJointTrajectory

    from acti_bringup.serving.adapter import action_server
    node = rclpy.create_node("bare_follow")

    def execute(goal_handle):
        goal_handle.succeed()
        return FollowJointTrajectory.Result()
    node.bare_server = action_server(node, FollowJointTrajectory, "~/follow_joint_trajectory",
                                     execute)
    return node


def replay_node(names: list[str]) -> rclpy.node.Node:
    """The services `names`, each answering one reply: a getter's fetched once from the running
    job, another operation's an OK reply that accepted nothing. With the job's QoS and its
    default introspection (and, given `--nice`, its niceness), so that the ratio to it is the
    node's own cost, not a setting's."""
    from acti_bringup.harness import RosClient
    from acti_bringup.recording.introspection import introspect
    from acti_bringup.recording.job import RecordingConfig
    from acti_bringup.serving.adapter import SERVICE_QOS
    fetch = RosClient("bare_replay_fetch")
    replies = {}
    for name in names:
        srv_type = SERVICES[name]
        if name.rsplit("/", 1)[1].startswith("get_"):
            replies[name] = fetch.call(srv_type, name)
        else:
            replies[name] = srv_type.Response()
            replies[name].motion_id = 1
    fetch.close()
    node = rclpy.create_node("bare_replay")
    for name in names:
        node.create_service(SERVICES[name], REPLAY + name, lambda _req, _resp, r=replies[name]: r,
                            qos_profile=SERVICE_QOS)
    introspect([node], RecordingConfig.service_introspection)
    return node


NICE = "--nice="


def main() -> None:
    args = rclpy.utilities.remove_ros_args(sys.argv)
    kind = args[1] if len(args) > 1 else KIND
    nice = [int(a.removeprefix(NICE)) for a in args if a.startswith(NICE)]
    init(sys.argv)
    if kind == "replay":
        node = replay_node([a for a in args[2:] if not a.startswith(NICE)]
                           or [name for name, _ in GETTERS])
    elif kind == "follow":
        node = follow_node()
    else:
        node = trigger_node()
    if nice and not set_niceness(nice[-1], print):
        raise SystemExit(f"niceness {nice[-1]} refused")
    executor = EXECUTORS[{"replay": KIND, "follow": "single"}.get(kind, kind)]()
    executor.add_node(node)
    loop = SpinLoop(executor, "bare").start()
    try:
        wait_for_signal(lambda: loop.alive)
    finally:
        loop.stop()
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
