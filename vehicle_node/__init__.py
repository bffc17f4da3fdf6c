"""vehicle_node: the VehicleService of the mobile base as ROS 2 services."""
