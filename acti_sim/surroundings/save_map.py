"""Write the Nav2 map-server pair (.yaml + .pgm) of a world file, as `map` has it:

    python -m acti_sim.surroundings.save_map config/worlds/room.yaml maps/room.yaml [--resolution 0.05]
"""
from __future__ import annotations

import argparse
import sys

from acti_sim.surroundings.occupancy import rasterise, write_map_server_pair
from acti_sim.surroundings.worldfile import WorldFileError, load_world


def main(args: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("world", help="the world file")
    parser.add_argument("out", help="the map's .yaml (the .pgm goes beside it)")
    parser.add_argument("--resolution", type=float, default=0.05, help="cell size [m] (0.01 … 1)")
    a = parser.parse_args(args)
    if not 0.01 <= a.resolution <= 1.0:
        parser.error(f"--resolution {a.resolution:g}: it must be within 0.01 … 1 m")
    try:
        grid = rasterise(load_world(a.world), a.resolution)
    except WorldFileError as e:
        print(f"save_map: {e}", file=sys.stderr)
        return 2
    pgm = write_map_server_pair(grid, a.out)
    print(f"wrote {a.out} and {pgm} ({grid.width} × {grid.height} cells of {a.resolution:g} m)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
