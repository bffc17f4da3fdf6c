"""Following joint trajectories (ROS's FollowJointTrajectory, without ROS): validation by
joint_trajectory_controller's rules, its interpolation, limit checks and tolerances, and the one
arm motion that follows a trajectory through the arm's motion queue."""
