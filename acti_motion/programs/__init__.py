"""STROLIC programs on the arm: the robot host (ED functions, `robot`) and one program run (`run`)."""
