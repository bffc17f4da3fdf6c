"""Baseline for the /clock gaps of `bench_control_plane.py`: a bare process that only publishes a
rosgraph_msgs/Clock on /bare_clock every period, scheduled as the job's control loop is in that
bench (niceness -10, SCHED_FIFO 10) and sharing nothing with the job. Its largest silence in a
case is what the machine itself allowed then:

    python -m bench.clock_floor [period_s [fifo_priority]]   (defaults 0.004: the job's 250 Hz;
                                                             10; 0: ordinary scheduling, as the
                                                             job's loop by default)
"""
import sys
import time

import rclpy
from rosgraph_msgs.msg import Clock

from acti_bringup.priority import set_fifo, set_niceness
from acti_bringup.serving.spinning import init, stop_requested

TOPIC = "/bare_clock"
FIFO_PRIORITY = 10           # also the job's control_fifo_priority in bench_control_plane.py
NICENESS = -10               # the job's


def main() -> None:
    args = rclpy.utilities.remove_ros_args(sys.argv)
    period = float(args[1]) if len(args) > 1 else 0.004
    fifo = int(args[2]) if len(args) > 2 else FIFO_PRIORITY
    init(sys.argv)
    node = rclpy.create_node("bare_clock")
    publisher = node.create_publisher(Clock, TOPIC, 10)
    set_niceness(NICENESS, print)
    set_fifo(fifo, print)
    due = time.monotonic()
    try:
        while not stop_requested():
            due += period
            time.sleep(max(0.0, due - time.monotonic()))
            publisher.publish(Clock())
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
