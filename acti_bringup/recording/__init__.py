"""Recording the job as rosbag2 does, over rclpy: the recorder node, the service and action
introspection of the job's own nodes, and the replay of a recording (`acti_record` writes and
reads the files)."""
