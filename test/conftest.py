"""Test settings shared by every test: DDS kept on this machine and on a domain of this run only.

Set before rclpy is imported anywhere, so the test process and the nodes it starts agree.
"""
import os
import sys

_here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, _here)
sys.path.insert(1, os.path.dirname(_here))

os.environ.setdefault("ROS_DOMAIN_ID", str(1 + os.getpid() % 100))
os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
os.environ["FASTDDS_BUILTIN_TRANSPORTS"] = "UDPv4"

pytest_plugins = ["ros_harness"]
