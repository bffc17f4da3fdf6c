"""Record the robot: every topic (or the ones named), the service calls of both nodes and the
actions' goals, feedback and results, into an MCAP file that `ros2 bag`, Foxglove and rosbags
open (docs/recording.md). Ends on Ctrl-C or SIGTERM with a complete file.

    python -m acti_bringup.record OUT.mcap [TOPIC ...] [--max-size MB] [--max-duration S]
        [--compression none|zstd|lz4] [--ros-args ...]
"""
from __future__ import annotations

import argparse
import shlex
import sys

import rclpy
from rclpy.executors import SingleThreadedExecutor

from acti_bringup.recording.recorder import Recorder
from acti_bringup.serving.spinning import SpinLoop, catch_signals, init, wait_for_signal
from acti_record.reading import REINDEX_COMMAND
from acti_record.writing import COMPRESSIONS, Recording


def parse(args: list[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="python -m acti_bringup.record",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("path", metavar="OUT.mcap", help="the recording")
    parser.add_argument("topics", metavar="TOPIC", nargs="*",
                        help="topics to record (default: all, hidden ones included)")
    parser.add_argument("--max-size", type=float, default=0.0, metavar="MB",
                        help="start a new file (OUT_0.mcap, OUT_1.mcap …) at this size")
    parser.add_argument("--max-duration", type=float, default=0.0, metavar="S",
                        help="start a new file after this many seconds")
    parser.add_argument("--compression", choices=list(COMPRESSIONS), default="none",
                        help="chunk compression (default none, as rosbag2's)")
    return parser.parse_args(args)


def wanted_topics(topics: list[str]):
    """Which topics to record: the named ones (with or without the leading /), or all."""
    names = {t if t.startswith("/") else f"/{t}" for t in topics}
    return (lambda name: name in names) if names else (lambda name: True)


def main(args: list[str] | None = None) -> None:
    argv = sys.argv if args is None else args
    own = argv[1:argv.index("--ros-args")] if "--ros-args" in argv else argv[1:]
    options = parse(own)
    catch_signals()             # from here on SIGINT/SIGTERM close the file (once it is open)
    try:
        recording = Recording(options.path, int(options.max_size * 1e6), options.max_duration,
                              options.compression)
    except (OSError, ValueError) as e:
        sys.exit(f"record: cannot record to {options.path}: {getattr(e, 'strerror', None) or e}")
    for path, kept in recording.kept:
        print(f"record: {path} was cut short (its recorder killed): kept as {kept}; "
              f"`{REINDEX_COMMAND} {shlex.quote(kept)}` makes it whole", file=sys.stderr)
    init([argv[0], *argv[argv.index("--ros-args"):]] if "--ros-args" in argv else argv[:1])
    node = rclpy.create_node("acti_recorder")
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    Recorder(node, recording, wanted_topics(options.topics))
    loop = SpinLoop(executor, "record").start()
    node.get_logger().info(f"recording to {options.path}")
    try:
        wait_for_signal(lambda: loop.alive)
    finally:
        loop.stop()
        executor.shutdown()
        recording.close()
        node.destroy_node()
        rclpy.try_shutdown()
    print(f"recorded {recording.messages} messages to {', '.join(recording.paths)}")


if __name__ == "__main__":
    main()
