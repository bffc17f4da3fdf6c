"""The robot's surroundings, without ROS: the world file of static obstacles (`worldfile`), its
occupancy grid (`occupancy`) and the laser scanner that sees them (`scanner`)."""
