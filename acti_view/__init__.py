"""ROS-free pictures of the running robot: the live browser view (viser), the PNG snapshot."""
