"""set_velocity on a cruising base answers without waiting for its re-plan, over DDS.

1.4.32: the answer says whether the value was set (真：引数で指定した値が正常に設定された), and a
moving base then changes speed to match (移動中に実行すると…設定値に一致させます). The re-plan of
a running cruise is a TOPP-RA timing in the base's planning process: here that process is
frozen (SIGSTOP), so any plan waits for it; set_velocity must still answer true, the simulation
must keep publishing /clock, and once the process runs again the base takes the new speed."""
from __future__ import annotations

import os
import signal

from acti_msgs import srv
from acti_msgs.msg import VehiclePoint, VehicleVelocity
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock

from ros_harness import node_fixture, wait_until

vehicle = node_fixture("vehicle_node")
BASE = "/vehicle_node/"
READY, BUSY = 0x010, 0x011


def planning_process(parent: int) -> int:
    """The pid of the base's planning process (acti_motion.vehicle.planner): the spawned child
    of the node that is not multiprocessing's resource tracker."""
    for pid in filter(str.isdigit, os.listdir("/proc")):
        try:
            with open(f"/proc/{pid}/stat") as f:
                ppid = int(f.read().rsplit(")", 1)[1].split()[1])
            with open(f"/proc/{pid}/cmdline", "rb") as f:
                command = f.read().decode(errors="replace")
        except OSError:
            continue
        if ppid == parent and "spawn_main" in command:
            return int(pid)
    raise AssertionError("the base's planning process was not found")


def test_set_velocity_answers_while_its_replan_cannot_run(ros, vehicle):
    def call(name, srv_type, **fields):
        return ros.call(srv_type, BASE + name, **fields)

    def velocity(translation: float) -> VehicleVelocity:
        return VehicleVelocity(translation=translation, rotation=45.0)

    speeds, clocks = [], []
    odom = ros.node.create_subscription(Odometry, "/odom",
                                        lambda m: speeds.append(m.twist.twist.linear.x), 10)
    clock = ros.node.create_subscription(Clock, "/clock", lambda m: clocks.append(m), 10)
    try:
        assert call("set_power", srv.VehicleSetPower, on_off=True).success
        assert call("set_servo", srv.VehicleSetServo, on_off=True).success
        assert wait_until(lambda: call("get_state", srv.VehicleGetState).state == READY, 30.0)
        assert call("set_velocity", srv.VehicleSetVelocity, vel=velocity(250.0)).success
        here = call("get_position", srv.VehicleGetPosition).pos
        for dx, dy in ((2000.0, 300.0), (20000.0, 0.0)):      # a long cruise, mostly straight
            point = VehiclePoint(x=here.x + dx, y=here.y + dy)
            assert call("move_cruise_abs", srv.VehicleMoveCruiseAbs, cruise_point=point).success
        assert ros.spin_until(lambda: speeds and speeds[-1] > 0.2, 60.0), "the cruise did not start"

        worker = planning_process(vehicle.proc.pid)
        os.kill(worker, signal.SIGSTOP)                 # every plan from now on waits
        try:
            reply = call("set_velocity", srv.VehicleSetVelocity, vel=velocity(600.0))
            assert reply.success, reply.message
            assert call("get_state", srv.VehicleGetState).state == BUSY
            seen = len(clocks)
            assert ros.spin_until(lambda: len(clocks) > seen + 20, 30.0), "/clock stopped"
            assert speeds[-1] < 0.35, "the new speed came without its plan"
        finally:
            os.kill(worker, signal.SIGCONT)
        assert ros.spin_until(lambda: speeds and speeds[-1] > 0.5, 60.0), \
            f"the cruise never took the new speed (last {speeds[-1]:.3f} m/s)"
    finally:
        call("stop", srv.VehicleStop)
        ros.node.destroy_subscription(odom)
        ros.node.destroy_subscription(clock)
    assert vehicle.alive()
