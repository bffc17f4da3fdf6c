"""acti_middle_node: the ACT common port and middle-level motion port as ROS 2 services."""
