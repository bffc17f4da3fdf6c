"""Render the robot to a PNG: a fresh world (no running job is touched) with the arm at its
start posture, or at the joints given, after the physics settled; with a world file's
obstacles and a camera that takes them in when one is given.

    python -m acti_bringup.visual.snapshot OUT.png [--joints J1 … J7 (degree)] [--size W H]
        [--world config/worlds/room.yaml]
"""
from __future__ import annotations

import argparse

from acti_bringup.visual.camera import MAX_PIXELS
from acti_motion.arm.core import ArmConfig, ArmCore
from acti_motion.executor import MotionExecutor
from acti_sim.world import World
from acti_bringup.simulation import world_path
from acti_sim.surroundings.worldfile import WorldFileError, WorldSpec, build_world, load_world
from acti_view.snapshot import write_png


def overview(spec: WorldSpec) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """(eye, target): above a corner of the world, looking at its middle."""
    x0, y0, x1, y1 = spec.bounds() or (-1.0, -1.0, 1.0, 1.0)
    cx, cy, span = (x0 + x1) / 2, (y0 + y1) / 2, max(x1 - x0, y1 - y0)
    return (cx - 0.35 * span, cy - 0.75 * span, 0.75 * span), (cx, cy, 0.0)

SETTLE_STEPS = 240


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(prog="python -m acti_bringup.visual.snapshot",
                                     description=__doc__.splitlines()[0])
    parser.add_argument("out", help="the PNG to write")
    parser.add_argument("--joints", type=float, nargs=7, metavar="DEG",
                        default=ArmConfig().initial_joints_deg, help="arm joints [degree]")
    parser.add_argument("--size", type=int, nargs=2, default=(800, 600), metavar=("W", "H"))
    parser.add_argument("--world", help="a world file whose obstacles to show (docs/world.md)")
    args = parser.parse_args(argv)
    width, height = args.size
    if not (0 < width and 0 < height and width * height <= MAX_PIXELS):
        parser.error(f"--size {width} {height}: both must be positive, at most {MAX_PIXELS} px "
                     "in all")
    try:
        spec = load_world(world_path(args.world)) if args.world else None
    except WorldFileError as e:
        parser.error(str(e))
    world = World()
    try:
        if spec is not None:
            build_world(world, spec)
        executor = MotionExecutor(world, real_time_factor=0.0)
        try:
            ArmCore(executor, ArmConfig(initial_joints_deg=tuple(args.joints)))
        except ValueError as e:     # the core names its parameter: say the option
            parser.error(f"--joints {' '.join(f'{q:g}' for q in args.joints)}: "
                         f"{str(e).replace('initial_joints_deg', 'the joints')}")
        for _ in range(SETTLE_STEPS):
            executor.step()
        try:
            write_png(world, args.out, width, height, *(overview(spec) if spec else ()))
        except OSError as e:
            parser.error(f"cannot write {args.out}: {e.strerror or e}")
    finally:
        world.close()
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
