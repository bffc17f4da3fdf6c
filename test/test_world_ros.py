"""The base in a world over DDS (issue 31): the scan against the room's geometry, the map, the
TF chain map → odom → base_link → base_scan on simulated time, the obstacle zones (caution speed,
stop before contact, Stuck and its alarm, the way out), cmd_vel as Twist and TwistStamped,
/initialpose, a bad world file, and the Nav2 parameters file against what the job offers."""
import math
import os
import time

import numpy as np
import pytest
import yaml
from acti_msgs import srv
from acti_msgs.msg import VehiclePoint, VehiclePosition, VehicleStatus, VehicleVelocity
from geometry_msgs.msg import PoseWithCovarianceStamped, Twist, TwistStamped
from nav_msgs.msg import OccupancyGrid, Odometry
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import LaserScan
from tf2_msgs.msg import TFMessage

from acti_bringup.visual.transforms import LATCHED_QOS, TF_QOS
from acti_sim.surroundings.occupancy import rasterise
from acti_sim.surroundings.worldfile import load_world
from acti_sim.world import ROOT
from ros_harness import NodeProcess, node_fixture, wait_until

ROOM = "config/worlds/room.yaml"
TABLE_FACE = 1.5                 # the table's near face, ahead of the start [m]
SCANNER = (0.24, 0.0, 0.22)      # base_scan in base_link (the URDF)
FRONT = 0.321                    # the bumper's face ahead of base_link [m]
room = node_fixture("vehicle_node", f"world:={ROOM}")
nav = node_fixture("vehicle_node", f"world:={ROOM}", "cmd_vel_stamped:=true",
                   "localization:=ground_truth", "use_sim_time:=true", "avoid_obstacles:=true",
                   namespace="/nav")

SERVICES = {"set_power": srv.VehicleSetPower, "set_servo": srv.VehicleSetServo,
            "get_state": srv.VehicleGetState, "set_velocity": srv.VehicleSetVelocity,
            "move_forward": srv.VehicleMoveForward, "clear_alarm": srv.VehicleClearAlarm,
            "get_active_alarm": srv.VehicleGetActiveAlarm, "move_jog": srv.VehicleMoveJog,
            "move_linear_abs": srv.VehicleMoveLinearAbs, "get_position": srv.VehicleGetPosition,
            "move_turn": srv.VehicleMoveTurn, "move_linear_rel": srv.VehicleMoveLinearRel,
            "move_circular_rel": srv.VehicleMoveCircularRel,
            "set_digital_sensor_lock": srv.VehicleSetDigitalSensorLock,
            "unlock": srv.VehicleUnlock}
# the "Ready only" moves (1.4.14, 1.4.17, 1.4.20, 1.4.21), each with a request that would move
READY_ONLY_MOVES = {"move_forward": dict(x=100.0), "move_turn": dict(theta=10.0),
                    "move_linear_rel": dict(pos=VehiclePosition(x=100.0, y=0.0, theta=0.0)),
                    "move_circular_rel": dict(center_point=VehiclePoint(x=0.0, y=500.0), theta=10.0)}


def call(ros, name, ns="", **fields):
    return ros.call(SERVICES[name], f"{ns}/vehicle_node/{name}", **fields)


def state(ros, ns=""):
    return call(ros, "get_state", ns).state


def ready(ros, ns=""):
    assert call(ros, "set_power", ns, on_off=True).success
    assert call(ros, "set_servo", ns, on_off=True).success
    assert wait_until(lambda: state(ros, ns) == 0x010, 30.0)   # a condition: 30 s under load


class Latest:
    """The messages of one topic, kept as they come (a deep history: a test process starved
    under load must not lose the samples it checks, such as a speed's peak)."""

    def __init__(self, ros, msg_type, topic, qos=1000):
        self.ros, self.got = ros, []
        self.sub = ros.node.create_subscription(msg_type, topic, self.got.append, qos)

    def wait(self, predicate=lambda msgs: bool(msgs), timeout=30.0):
        assert self.ros.spin_until(lambda: bool(self.got) and predicate(self.got), timeout), \
            f"not in {timeout} s: {self.got[-1] if self.got else 'nothing came'}"
        return self.got[-1]

    def close(self):
        self.ros.node.destroy_subscription(self.sub)


def test_scan_sees_the_room_at_its_distances(ros, room):
    scans = Latest(ros, LaserScan, "/scan")
    try:
        scan = scans.wait()
    finally:
        scans.close()
    assert scan.header.frame_id == "base_scan" and len(scan.ranges) == 360
    assert scan.angle_min == pytest.approx(-math.pi) and scan.angle_increment == pytest.approx(
        math.radians(1.0))

    def at(angle):
        return scan.ranges[round((angle - scan.angle_min) / scan.angle_increment)]
    # noise off: the exact faces, within the scan's resolution (1 cm: the base's settling)
    assert at(0.0) == pytest.approx(TABLE_FACE - SCANNER[0], abs=0.01)
    assert at(math.pi / 2) == pytest.approx(2.45, abs=0.01)           # the north wall's face
    assert at(-math.pi / 2) == pytest.approx(2.45, abs=0.01)          # the south wall's
    assert all(scan.range_min <= r <= scan.range_max for r in scan.ranges)    # a closed room


def test_map_is_the_world_rasterised(ros, room):
    maps = Latest(ros, OccupancyGrid, "/map", LATCHED_QOS)
    try:
        grid = maps.wait()
    finally:
        maps.close()
    expected = rasterise(load_world(os.path.join(ROOT, ROOM)), 0.05)
    assert grid.header.frame_id == "map" and grid.info.resolution == pytest.approx(0.05)
    assert (grid.info.width, grid.info.height) == (expected.width, expected.height)
    assert (grid.info.origin.position.x, grid.info.origin.position.y) == pytest.approx(expected.origin)
    cells = np.array(grid.data, np.int8).reshape(grid.info.height, grid.info.width)
    assert (cells == expected.cells).all()
    assert cells[expected.cell_of(1.8, 0.0)] == 100 and cells[expected.cell_of(0.0, 0.0)] == 0


def test_a_move_at_the_table_slows_stops_short_and_is_stuck_until_cleared(ros, room):
    """The obstacle zones over DDS, and (issue 35) the Ready-only moves refused in Stuck."""
    truth = Latest(ros, Odometry, "/vehicle_node/ground_truth")
    try:
        ready(ros)
        assert call(ros, "set_velocity", vel=VehicleVelocity(translation=600.0, rotation=45.0)).success
        first = call(ros, "move_forward", x=3000.0)
        assert first.success
        assert wait_until(lambda: state(ros) == 0x014, 60.0), "never Stuck"
        truth.wait(lambda m: len(m) > 10 and abs(m[-1].twist.twist.linear.x) < 1e-3
                   and abs(m[-10].twist.twist.linear.x) < 1e-3)
        samples = [(TABLE_FACE - FRONT - m.pose.pose.position.x, m.twist.twist.linear.x)
                   for m in truth.got]
        assert max(v for _, v in samples) > 0.5
        # the caution zone (0.8 m) once the limit had the braking distance from 0.6 to 0.2 m/s
        inside = [v for g, v in samples if g < 0.8 - (0.6 ** 2 - 0.2 ** 2) / 2 - 0.02]
        assert inside and max(inside) <= 0.2 * 1.05
        rest = samples[-1][0]
        assert 0.05 < rest < 0.3                    # stopped before contact, near stop_distance
        alarms = call(ros, "get_active_alarm", num_of_alarm=5)
        obstacle = [a for a in alarms.active_alarms if a.code == 121]
        assert obstacle and "range" in obstacle[0].source and "bearing" in obstacle[0].source
        assert state(ros) == 0x014
        # issue 35: the Ready-only moves are refused in Stuck (move_turn was accepted against the
        # wall): false, nothing queued, no motion id given
        for name, fields in READY_ONLY_MOVES.items():
            r = call(ros, name, **fields)
            assert not r.success and r.motion_id == 0, (name, r.message)
            assert f"the base is Stuck: {name} needs Ready" in r.message, r.message
            assert state(ros) == 0x014
        # the way out: clear_alarm, then a move away (the id after the first move's: the
        # refusals took none)
        assert call(ros, "clear_alarm").success and state(ros) == 0x010
        back = call(ros, "move_forward", x=-500.0)
        assert back.success and back.motion_id == first.motion_id + 1
        assert wait_until(lambda: state(ros) == 0x010, 30.0)
        truth.wait(lambda m: m[-1].pose.pose.position.x < TABLE_FACE - FRONT - rest - 0.45)
    finally:
        truth.close()


TABLE_SIDE = 0.5                 # the table's north face (y) [m]
RAYS_ACROSS = 0.35               # the zones' rays span the footprint's width (the wheels' boxes) [m]
BUMPER_REACH = math.hypot(FRONT, 0.22)   # the bumper's corner from base_link: 0.389 m
BESIDE = 0.87                    # y of a lane past the table: its side 0.37 m from base_link


def at_rest(ros, truth):
    assert wait_until(lambda: state(ros) == 0x010, 60.0), (
        call(ros, "get_active_alarm", num_of_alarm=5),
        truth.got[-1].pose.pose if truth.got else None)


def test_a_contact_locks_the_base_and_clear_alarm_clears_its_alarm_not_the_lock(ros, room):
    """Issue 35 over DDS: after a bumper contact (alarm 301, Locked), clear_alarm clears every
    alarm (1.4.1), the contact's too, but the base stays Locked and refuses moves until unlock
    (table 7, Locked: 解除指令受信まで; docs/interfaces.md). The contact: beside the table, a turn
    in place (the obstacle zones watch translations only) sweeps the bumper's corner into it."""
    truth = Latest(ros, Odometry, "/vehicle_node/ground_truth")
    try:
        ready(ros)
        assert call(ros, "set_velocity",
                    vel=VehicleVelocity(translation=600.0, rotation=45.0)).success
        # a lane past the table, its side out of the zones' rays but within the bumper's sweep
        for x in (600.0, 1800.0):
            assert call(ros, "move_linear_abs", pos=VehiclePosition(x=x, y=1000.0 * BESIDE,
                                                                    theta=0.0)).success
            at_rest(ros, truth)
        true = truth.wait(lambda m: m[-1].pose.pose.position.x > 1.7        # beside the table
                          and abs(m[-1].twist.twist.linear.x) < 1e-3).pose.pose
        assert true.position.x < 1.9, true
        gap = true.position.y - TABLE_SIDE
        assert RAYS_ACROSS + 0.005 < gap < BUMPER_REACH - 0.005, true
        assert call(ros, "set_digital_sensor_lock", on_off=True).success
        assert call(ros, "move_turn", theta=-90.0).success                 # towards the table
        assert wait_until(lambda: state(ros) == 0x017, 60.0), state(ros)   # Locked
        n = len(truth.got)
        truth.wait(lambda m: len(m) > n + 10 and all(abs(s.twist.twist.angular.z) < 1e-3
                                                     for s in m[-10:]))      # at rest
        alarms = call(ros, "get_active_alarm", num_of_alarm=5)
        assert [(a.code, a.type) for a in alarms.active_alarms] == [(301, 1)], alarms  # a FAULT
        r = call(ros, "move_forward", x=-100.0)
        assert not r.success and r.motion_id == 0 and "unlock" in r.message, r.message
        # clear_alarm: every alarm, the contact's too …
        r = call(ros, "clear_alarm")
        assert r.success and r.message == "still active: Locked until unlock (a contact)", r.message
        assert call(ros, "get_active_alarm", num_of_alarm=5).num_of_active_alarm == 0
        # … but Locked is left by unlock only (1.4.34)
        assert state(ros) == 0x017
        r = call(ros, "move_turn", theta=10.0)
        assert not r.success and r.motion_id == 0 and "unlock" in r.message, r.message
        assert call(ros, "unlock").success
        at_rest(ros, truth)
        # the way out: turn back to face along the lane (away from the table), back out of it
        theta = call(ros, "get_position").pos.theta
        assert -90.0 < theta < -5.0, theta                                 # stopped on the way
        assert call(ros, "move_turn", theta=-theta).success
        at_rest(ros, truth)
        assert call(ros, "move_forward", x=-1200.0).success
        at_rest(ros, truth)
    finally:
        call(ros, "set_digital_sensor_lock", on_off=False)
        truth.close()


def publish_for(ros, publisher, msg, seconds):
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        publisher.publish(msg)
        ros.executor.spin_once(timeout_sec=0.05)


def yaw(q):
    return math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))


@pytest.mark.parametrize("stamped", [False, True])
def test_cmd_vel_as_twist_or_twist_stamped(ros, room, nav, stamped):
    ns = "/nav" if stamped else ""
    odom = Latest(ros, Odometry, f"{ns}/odom")
    cmd = ros.node.create_publisher(TwistStamped if stamped else Twist, f"{ns}/cmd_vel", 10)
    try:
        ready(ros, ns)
        before = yaw(odom.wait().pose.pose.orientation)
        twist = Twist()
        twist.angular.z = 0.5                         # in place: nothing in the way
        msg = TwistStamped(twist=twist) if stamped else twist
        publish_for(ros, cmd, msg, 1.0)
        odom.wait(lambda m: abs(yaw(m[-1].pose.pose.orientation) - before) > 0.2)
        assert wait_until(lambda: state(ros, ns) == 0x010, 10.0)
    finally:
        odom.close()
        ros.node.destroy_publisher(cmd)


def transform_of(msgs, parent, child):
    for m in reversed(msgs):
        for t in m.transforms:
            if t.header.frame_id == parent and t.child_frame_id == child:
                return t
    return None


def planar(t):
    tr = t.transform.translation
    return tr.x, tr.y, yaw(t.transform.rotation)


def compose(a, b):
    x, y, th = a
    return (x + math.cos(th) * b[0] - math.sin(th) * b[1],
            y + math.sin(th) * b[0] + math.cos(th) * b[1], th + b[2])


def test_tf_chain_on_sim_time_and_initialpose(ros, nav):
    tf, static = Latest(ros, TFMessage, "/nav/tf", TF_QOS), Latest(ros, TFMessage, "/nav/tf_static", LATCHED_QOS)
    clock, truth = Latest(ros, Clock, "/nav/clock"), Latest(ros, Odometry, "/nav/vehicle_node/ground_truth")
    pose_out = ros.node.create_publisher(PoseWithCovarianceStamped, "/nav/initialpose", 10)
    try:
        chain = [("map", "odom"), ("odom", "base_link")]
        tf.wait(lambda m: all(transform_of(m, *link) for link in chain))
        scan_mount = static.wait(lambda m: transform_of(m, "base_link", "base_scan"))
        mount = transform_of(static.got, "base_link", "base_scan").transform.translation
        assert (mount.x, mount.y, mount.z) == pytest.approx(SCANNER)
        now = clock.wait().clock
        for link in chain:                        # stamped in simulated time, not wall time
            stamp = transform_of(tf.got, *link).header.stamp
            assert abs((stamp.sec + stamp.nanosec * 1e-9) - (now.sec + now.nanosec * 1e-9)) < 5.0
        assert scan_mount is not None
        # ground truth: map → base_link is the simulator's pose of the base
        true = truth.wait().pose.pose
        in_map = compose(planar(transform_of(tf.got, *chain[0])), planar(transform_of(tf.got, *chain[1])))
        assert in_map[:2] == pytest.approx((true.position.x, true.position.y), abs=0.01)
        # /initialpose moves the map: the base is where it says, in the map
        msg = PoseWithCovarianceStamped()
        msg.header.frame_id = "map"
        msg.pose.pose.position.x, msg.pose.pose.position.y = 1.0, 0.5
        msg.pose.pose.orientation.z, msg.pose.pose.orientation.w = math.sin(math.pi / 4), math.cos(math.pi / 4)
        pose_out.publish(msg)

        def placed(msgs):
            a, b = transform_of(msgs, *chain[0]), transform_of(msgs, *chain[1])
            x, y, th = compose(planar(a), planar(b))
            return abs(x - 1.0) < 0.01 and abs(y - 0.5) < 0.01 and abs(th - math.pi / 2) < 0.01
        tf.wait(placed)
    finally:
        for sub in (tf, static, clock, truth):
            sub.close()
        ros.node.destroy_publisher(pose_out)


def test_avoid_detours_around_the_table_to_the_target(ros, nav):
    """With avoid_obstacles: the table is in the way of a straight move to behind it."""
    states, truth = Latest(ros, VehicleStatus, "/nav/vehicle_node/state"), \
        Latest(ros, Odometry, "/nav/vehicle_node/ground_truth")
    try:
        ready(ros, "/nav")
        assert call(ros, "set_velocity", "/nav", vel=VehicleVelocity(translation=400.0, rotation=45.0)).success
        assert call(ros, "move_linear_abs", "/nav", pos=VehiclePosition(x=2900.0, y=0.0, theta=0.0)).success
        states.wait(lambda m: m[-1].state == 0x016, 60.0)                       # Avoid
        states.wait(lambda m: m[-1].state in (0x010, 0x014), 120.0)             # then Ready
        assert states.got[-1].state == 0x010, call(ros, "get_active_alarm", "/nav", num_of_alarm=5)
        assert 0x014 not in [m.state for m in states.got]                       # never Stuck
        p = call(ros, "get_position", "/nav").pos
        assert (p.x, p.y) == pytest.approx((2900.0, 0.0), abs=30.0)
        # around the table (x 1.5 … 2.1, y ±0.5), never through it: the base's footprint stayed out
        for m in truth.got:
            x, y = m.pose.pose.position.x, m.pose.pose.position.y
            assert not (1.5 - FRONT < x < 2.1 + 0.3 and abs(y) < 0.5 + 0.35), (x, y)
    finally:
        states.close()
        truth.close()


def test_a_bad_world_file_is_one_line_and_exit_status_2(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("boxes:\n  - {name: desk, size: [1.0, -0.5, 0.7], pose: [1, 0, 0]}\n")
    node = NodeProcess("vehicle_node", str(tmp_path / "node.log"), f"world:={bad}")
    try:
        assert node.proc.wait(timeout=60.0) == 2, node.log()
    finally:
        node.stop()
    fatal = [line for line in node.log().splitlines() if "[FATAL]" in line]
    assert len(fatal) == 1, node.log()
    assert f"world file {bad}: boxes[0] ('desk'): size is [1.0, -0.5, 0.7]: sizes must be > 0 m" \
        in fatal[0]
    assert "Traceback" not in node.log()


def values_of(tree, keys):
    """Every value of these keys anywhere in the parameter tree."""
    if isinstance(tree, dict):
        for k, v in tree.items():
            if k in keys and isinstance(v, str):
                yield v
            yield from values_of(v, keys)


def test_nav2_params_name_only_frames_and_topics_the_job_has(ros, room):
    with open(os.path.join(ROOT, "config", "nav2", "nav2_params.yaml")) as f:
        params = yaml.safe_load(f)
    for server in ("bt_navigator", "controller_server", "planner_server", "behavior_server",
                   "velocity_smoother"):
        assert "ros__parameters" in params[server], server
    tf = Latest(ros, TFMessage, "/tf", TF_QOS)
    try:
        frames = {t for m in [tf.wait(lambda m: transform_of(m, "map", "odom"))] for t in
                  [x.header.frame_id for x in m.transforms] + [x.child_frame_id for x in m.transforms]}
    finally:
        tf.close()
    named_frames = set(values_of(params, {"global_frame", "robot_base_frame", "local_frame"}))
    assert named_frames and named_frames <= frames, named_frames - frames
    topics = {}
    wait_until(lambda: topics.update(ros.node.get_topic_names_and_types()) or "/scan" in topics, 20.0)
    named_topics = {"/" + t for t in values_of(params, {"topic", "odom_topic", "map_topic"})}
    assert named_topics <= set(topics), named_topics - set(topics)
    assert "/cmd_vel" in topics
    # the base's limits (config/acti_ros2.yaml) and the footprint's circumscribed circle
    smoother = params["velocity_smoother"]["ros__parameters"]
    assert smoother["max_velocity"] == pytest.approx([1.0, 0.0, math.radians(90.0)], abs=1e-4)
    assert smoother["max_accel"] == pytest.approx([1.0, 0.0, math.radians(180.0)], abs=1e-4)
    radius = params["global_costmap"]["global_costmap"]["ros__parameters"]["robot_radius"]
    assert radius == pytest.approx(math.hypot(FRONT, 0.35), abs=0.01)
