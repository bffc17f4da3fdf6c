"""The manipulator: the ACT port core (`core`), its kinematics, poses, trajectories and blending."""
