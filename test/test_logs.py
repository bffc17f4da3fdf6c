"""What the ROS-free cores log (Python's `logging`) reaches the ROS logger of a node, with its
severity and name, and a line that repeats is said at most once every REPEAT_S."""
import logging

from rclpy.logging import get_logger

from acti_bringup.serving.logs import REPEAT_S, RosLogging, route_python_logging


class Clock:
    def __init__(self) -> None:
        self.now = 1000.0

    def __call__(self) -> float:
        return self.now


def fall_behind(ms: int) -> None:
    logging.getLogger("acti_motion").warning(f"the control loop fell {ms} ms behind real time")


def test_a_core_record_goes_through_the_ros_logger_once_per_repeat_interval(capfd):
    clock = Clock()
    root = logging.getLogger()
    handler = RosLogging(get_logger("log_test_node"), clock)
    root.addHandler(handler)
    try:
        for ms in (51, 52, 53):
            fall_behind(ms)
        clock.now += REPEAT_S
        fall_behind(60)
        logging.getLogger("acti_motion").error("another line")
    finally:
        root.removeHandler(handler)
    lines = capfd.readouterr().err.splitlines()
    said = [line for line in lines if "log_test_node.acti_motion" in line]
    assert len(said) == 3, lines
    assert said[0].startswith("[WARN] [") and said[0].endswith("fell 51 ms behind real time")
    assert said[1].endswith(f"fell 60 ms behind real time (2 more like it in the "
                            f"{REPEAT_S:.0f} s before, not shown)"), said[1]
    assert said[2].startswith("[ERROR] [") and said[2].endswith("another line")


def test_routing_again_replaces_the_handler():
    route_python_logging(get_logger("first"))
    route_python_logging(get_logger("second"))
    ours = [h for h in logging.getLogger().handlers if isinstance(h, RosLogging)]
    assert [h.logger.name for h in ours] == ["second"]
    logging.getLogger().removeHandler(ours[0])
