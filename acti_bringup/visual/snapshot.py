"""Render the robot to a PNG: a fresh world (no running job is touched) with the arm at its
start posture, or at the joints given, after the physics settled.

    python -m acti_bringup.visual.snapshot OUT.png [--joints J1 … J7 (degree)] [--size W H]
"""
from __future__ import annotations

import argparse

from acti_bringup.visual.camera import MAX_PIXELS
from acti_motion.arm.core import ArmConfig, ArmCore
from acti_motion.executor import MotionExecutor
from acti_sim.world import World
from acti_view.snapshot import write_png

SETTLE_STEPS = 240


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(prog="python -m acti_bringup.visual.snapshot",
                                     description=__doc__.splitlines()[0])
    parser.add_argument("out", help="the PNG to write")
    parser.add_argument("--joints", type=float, nargs=7, metavar="DEG",
                        default=ArmConfig().initial_joints_deg, help="arm joints [degree]")
    parser.add_argument("--size", type=int, nargs=2, default=(800, 600), metavar=("W", "H"))
    args = parser.parse_args(argv)
    width, height = args.size
    if not (0 < width and 0 < height and width * height <= MAX_PIXELS):
        parser.error(f"--size {width} {height}: both must be positive, at most {MAX_PIXELS} px "
                     "in all")
    world = World()
    try:
        executor = MotionExecutor(world, real_time_factor=0.0)
        try:
            ArmCore(executor, ArmConfig(initial_joints_deg=tuple(args.joints)))
        except ValueError as e:     # the core names its parameter: say the option
            parser.error(f"--joints {' '.join(f'{q:g}' for q in args.joints)}: "
                         f"{str(e).replace('initial_joints_deg', 'the joints')}")
        for _ in range(SETTLE_STEPS):
            executor.step()
        try:
            write_png(world, args.out, width, height)
        except OSError as e:
            parser.error(f"cannot write {args.out}: {e.strerror or e}")
    finally:
        world.close()
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
