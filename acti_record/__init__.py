"""ROS-free recording: MCAP files as rosbag2 writes them (profile ros2, ros2msg schemas, cdr
messages, rosbag2's channel metadata), split by size or duration, read back even when cut short
by a kill and written again whole (`reindexing`, as `ros2 bag reindex`), and recorded service
answers compared with replayed ones. The ROS side (subscriptions, service introspection, the
replay's clients) is `acti_bringup.recording`."""
