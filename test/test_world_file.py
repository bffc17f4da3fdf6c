"""The world file (acti_sim.surroundings): parsing and its refusals, the obstacles in PyBullet,
the occupancy grid and the map-server pair, and the laser scanner against known geometry."""
import math

import numpy as np
import pytest

from acti_sim.surroundings.occupancy import OCCUPIED, rasterise, write_map_server_pair
from acti_sim.surroundings.scanner import LaserScanner, ScanGeometry
from acti_sim.surroundings.worldfile import (Box, Cylinder, WorldFileError, WorldSpec, build_world,
                                             load_world, parse_world)
from acti_sim.world import ROOT, World

ROOM = f"{ROOT}/config/worlds/room.yaml"
SCANNER_X = 0.24          # base_scan ahead of base_link (the URDF)


def test_shipped_worlds_load():
    assert load_world(f"{ROOT}/config/worlds/empty.yaml") == WorldSpec(name="empty")
    room = load_world(ROOM)
    assert room.name == "room" and len(room.boxes) >= 5 and len(room.cylinders) >= 1
    assert Box("table", (0.6, 1.0, 0.75), (1.8, 0.0, 0.0)) in room.boxes


def test_an_empty_file_is_an_empty_world(tmp_path):
    path = tmp_path / "w.yaml"
    path.write_text("")
    assert load_world(str(path)) == WorldSpec()


@pytest.mark.parametrize("text, entry, words", [
    ("boxes: [{size: [1, 1], pose: [0, 0, 0]}]", "boxes[0]", "size is [1, 1]: a list of 3 numbers"),
    ("boxes: [{name: a, size: [1, 1, 0], pose: [0, 0, 0]}]", "boxes[0] ('a')", "sizes must be > 0"),
    ("boxes: [{size: [1, 1, 1]}]", "boxes[0]", "pose missing"),
    ("boxes: [{size: [1, 1, 1], pose: [0, 0, 0], colour: red}]", "boxes[0]", "unknown key colour"),
    ("cylinders: [{radius: .nan, height: 1, pose: [0, 0, 0]}]", "cylinders[0]", "must be finite"),
    ("cylinders: [{radius: 1, height: 1, pose: [0, 0, true]}]", "cylinders[0]", "3 numbers"),
    ("cylinders: [{radius: 1, height: 1, pose: [0, 0, 0], name: 5}]", "cylinders[0]", "not a string"),
    ("walls: []", "the file", "unknown key walls"),
    ("boxes: {a: 1}", "boxes", "a list of entries"),
    ("- 1", "the file", "a mapping"),
    ("boxes: [", "the file", "not YAML"),
])
def test_a_bad_file_names_the_file_the_entry_and_what(tmp_path, text, entry, words):
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    with pytest.raises(WorldFileError) as e:
        load_world(str(path))
    assert str(path) in str(e.value) and f": {entry}: " in str(e.value) and words in str(e.value)


def test_a_missing_file_is_refused(tmp_path):
    with pytest.raises(WorldFileError, match="No such file"):
        load_world(str(tmp_path / "none.yaml"))


def test_bounds_of_a_turned_box_and_a_cylinder():
    spec = WorldSpec(boxes=(Box("", (2.0, 1.0, 1.0), (1.0, 0.0, math.pi / 2)),),
                     cylinders=(Cylinder("", 0.5, 1.0, (-3.0, 0.0, 0.0)),))
    assert np.allclose(spec.bounds(), (-3.5, -1.0, 1.5, 1.0))


def test_occupancy_marks_every_cell_an_obstacle_overlaps():
    spec = parse_world({"boxes": [{"size": [0.02, 2.0, 1.0], "pose": [1.05, 0.0, 0.0]}],
                        "cylinders": [{"radius": 0.3, "height": 1.0, "pose": [-1.0, 0.5, 0.0]}]})
    grid = rasterise(spec, 0.1)
    occupied = grid.cells == OCCUPIED
    # the 2 cm wall closes one column of cells along its whole length (x 1.04 … 1.06: a cell's middle)
    r0, c = grid.cell_of(1.05, -0.95)
    r1, _ = grid.cell_of(1.05, 0.95)
    assert occupied[r0:r1 + 1, c].all()
    assert not occupied[r0:r1 + 1, c - 1].any() and not occupied[r0:r1 + 1, c + 1].any()
    assert occupied[grid.cell_of(-1.0, 0.5)] and occupied[grid.cell_of(-1.25, 0.5)]
    assert not occupied[grid.cell_of(-1.0, 0.5 + 0.45)]
    assert not occupied[grid.cell_of(0.0, 0.0)]          # the start is free
    # the grid holds everything, with a margin
    assert grid.origin[0] < -1.3 and grid.origin[0] + grid.width * 0.1 > 1.01


def test_map_server_pair(tmp_path):
    grid = rasterise(load_world(ROOM), 0.05)
    pgm = write_map_server_pair(grid, str(tmp_path / "room.yaml"))
    text = (tmp_path / "room.yaml").read_text()
    assert "image: room.pgm" in text and "resolution: 0.05" in text
    with open(pgm, "rb") as f:
        data = f.read()
    header = f"{grid.width} {grid.height}\n255\n".encode()
    pixels = np.frombuffer(data[data.index(header) + len(header):], np.uint8)
    image = pixels.reshape(grid.height, grid.width)[::-1]           # bottom row first again
    assert ((image == 0) == (grid.cells == OCCUPIED)).all()


@pytest.fixture
def room_world():
    world = World()
    build_world(world, load_world(ROOM))
    for _ in range(50):
        world.step()
    yield world
    world.close()


def test_scan_sees_the_room_at_its_distances(room_world):
    scanner = LaserScanner("base_scan", ScanGeometry(2 * math.pi, 360, 0.05, 10.0, 0.0), 0.1)
    scan = scanner.scan_now(room_world)
    angles = scanner.geometry.angles()
    ahead, left, behind = (int(np.argmin(np.abs(angles - a))) for a in (0.0, math.pi / 2, -math.pi))
    # table face x 1.5, north wall face y 2.45, west wall face x -2.0 (1 cm: the base's settling)
    assert scan.ranges[ahead] == pytest.approx(1.5 - SCANNER_X, abs=0.01)
    assert scan.ranges[left] == pytest.approx(2.45, abs=0.01)
    assert scan.ranges[behind] == pytest.approx(2.0 + SCANNER_X, abs=0.01)


def test_scan_leaves_out_the_robot_and_reports_no_return_as_inf():
    world = World()
    try:
        world.reset_arm(np.radians([0.0, 90.0, 0.0, 0.0, 0.0, 0.0, 0.0]))   # arm over the scanner
        world.step()
        scanner = LaserScanner("base_scan", ScanGeometry(2 * math.pi, 90, 0.05, 5.0, 0.0), 0.1)
        assert np.isinf(scanner.scan_now(world).ranges).all()
    finally:
        world.close()


def test_a_sweep_is_spread_over_the_steps_of_its_period(room_world):
    scanner = LaserScanner("base_scan", ScanGeometry(2 * math.pi, 360, 0.05, 10.0, 0.0), 0.1)
    calls, scan = 0, None
    while scan is None:
        scan = scanner.advance(room_world)
        calls += 1
        room_world.step()
    assert calls == pytest.approx(0.1 / room_world.time_step, abs=2)
    assert np.allclose(scan.ranges, scanner.scan_now(room_world).ranges, atol=1e-3)
    starts = [scan.start_time]                     # every 3rd step: sweeps a period apart
    while len(starts) < 4:
        for _ in range(3):
            room_world.step()
        done = scanner.advance(room_world)
        if done is not None:
            starts.append(done.start_time)
    assert np.diff(starts) == pytest.approx([0.1] * 3, abs=1e-9)


def test_noise_has_its_spread():
    geometry = ScanGeometry(2 * math.pi, 360, 0.05, 10.0, 0.02)
    world = World()
    try:
        build_world(world, load_world(ROOM))
        world.step()
        exact = LaserScanner("base_scan", ScanGeometry(2 * math.pi, 360, 0.05, 10.0, 0.0),
                             0.1).scan_now(world)
        noisy = LaserScanner("base_scan", geometry, 0.1).scan_now(world)
        assert np.std(noisy.ranges - exact.ranges) == pytest.approx(0.02, rel=0.25)
    finally:
        world.close()
