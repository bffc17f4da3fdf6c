"""What shows the robot: the live browser view node (`view`), the camera, `robot_description`
and TF for RViz (`robot_graph`, `transforms`), snapshots, and the headless browser that checks
the view."""
