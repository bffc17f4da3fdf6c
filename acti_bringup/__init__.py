"""ROS glue shared by both nodes: conversions, the table-driven service adapter, the simulation runtime."""
