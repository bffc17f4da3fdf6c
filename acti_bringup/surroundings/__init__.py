"""The base's surroundings on ROS: the laser scan, the world's map and the localisation Nav2
needs (the thin adapters of `acti_sim.surroundings`)."""
