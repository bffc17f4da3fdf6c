"""Replay a recording (`python -m acti_bringup.record`).

    python -m acti_bringup.replay FILE.mcap [--rate R] [--topics TOPIC ...]
        [--wait-for-subscribers S]
        republishes the recorded topics (not the hidden ones: service events, the actions'
        own topics) with their recorded timing, R times as fast
    python -m acti_bringup.replay FILE.mcap --requests [--rate R]
        sends the recorded service requests and action goals, and the messages of the topics
        the job listens to (cmd_vel …), to the running job in their recorded order and timing
        (on its simulated clock) and compares each answer with the recorded one (motion ids,
        stamps and durations not compared; states, flags, ids exactly; measured numbers within
        --tolerance plus how far the measured timing errors may have moved the device);
        prints every call's outcome, exit status 1 on any difference

A file that is not a recording: one line saying why, exit status 2.
"""
from __future__ import annotations

import argparse
import sys

import rclpy

from acti_bringup.record import wanted_topics
from acti_bringup.recording.replay import RequestReplay, is_hidden, republish
from acti_bringup.serving.spinning import init, stop_requested
from acti_record.calls import ABS_TOL
from acti_record.reading import BadRecording, read_recording

ANSWER_TIMEOUT_S = 120.0


def parse(args: list[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="python -m acti_bringup.replay",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("path", metavar="FILE.mcap", help="the recording (or its folder)")
    parser.add_argument("--requests", action="store_true",
                        help="replay the service calls and action goals, compare the answers")
    parser.add_argument("--rate", type=float, default=1.0, help="speed factor (default 1)")
    parser.add_argument("--topics", nargs="+", default=[], metavar="TOPIC",
                        help="the topics to republish (default: every topic not hidden)")
    parser.add_argument("--wait-for-subscribers", type=float, default=0.0, metavar="S",
                        help="before republishing, wait up to S seconds for a subscriber on "
                             "each topic (default 0)")
    parser.add_argument("--timeout", type=float, default=ANSWER_TIMEOUT_S, metavar="S",
                        help=f"longest wait for one answer (default {ANSWER_TIMEOUT_S:g} s)")
    parser.add_argument("--tolerance", type=float, default=ABS_TOL, metavar="T",
                        help="largest difference of two equal measured numbers, in the "
                             f"services' units (default {ABS_TOL:g}: mm, degree …), beside "
                             "what the replay's timing errors may have moved the device")
    options = parser.parse_args(args)
    if not options.rate > 0:
        parser.error("--rate must be positive")
    return options


def main(args: list[str] | None = None) -> None:
    argv = sys.argv if args is None else args
    ros_args = argv[argv.index("--ros-args"):] if "--ros-args" in argv else []
    options = parse(argv[1:len(argv) - len(ros_args)])
    try:
        contents = read_recording(options.path)
    except BadRecording as e:
        print(f"replay: {e}", file=sys.stderr)
        raise SystemExit(2)
    if contents.problem:
        print(f"replay: {contents.problem}", file=sys.stderr)
    init([argv[0], *ros_args])
    node = rclpy.create_node("acti_replay")
    try:
        if options.requests:
            replay = RequestReplay(node, contents, options.rate, options.timeout,
                                   options.tolerance, stop_requested)
            print(f"replaying {len(replay.calls)} calls of {options.path}")
            found = replay.run()
            print(f"{len(replay.calls)} calls, {len(found)} differences")
            status = 1 if found or stop_requested() else 0
        else:
            wanted = wanted_topics(options.topics) if options.topics else \
                (lambda topic: not is_hidden(topic))
            count = republish(node, contents, wanted, options.rate, stop_requested,
                              options.wait_for_subscribers)
            print(f"republished {count} messages of {options.path}")
            status = 0
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    raise SystemExit(status)


if __name__ == "__main__":
    main()
