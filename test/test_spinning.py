"""The serving planes (`acti_bringup.serving.spinning`) on rclpy's EventsExecutor, explicitly: a spin_once
loop serves services and timers and ends at once when stopped; a guard condition is what the
EventsExecutor cannot serve (why goals have a plane of their own); every way of running the
nodes ends cleanly on SIGINT and SIGTERM (exit 0, no traceback), and a start-up setting they
refuse ends them with one line and exit status 2."""
from __future__ import annotations

import signal
import subprocess
import sys
import time

import pytest
from acti_msgs.action import WaitMotion
from acti_msgs.srv import GetState, VehicleGetState
from rclpy.action import ActionServer
from std_srvs.srv import Trigger

from acti_bringup.harness import ROOT
from acti_bringup.serving.outbox import UnlockedActionHandle
from acti_bringup.serving.spinning import SPIN_TIMEOUT_S, Planes
from ros_harness import NodeProcess, wait_until


def test_a_spin_loop_serves_services_and_timers_and_stops_at_once(ros, events_loop):
    node, loop = events_loop
    ticks = []
    node.create_timer(0.01, lambda: ticks.append(time.monotonic()))

    def ping(_request, response):
        response.success = True
        return response
    node.create_service(Trigger, "~/ping", ping)
    loop.start()
    for _ in range(20):
        assert ros.call(Trigger, "/spin_loop_test/ping").success
    assert ros.spin_until(lambda: len(ticks) >= 10, 5.0), "the timer did not fire"
    t0 = time.monotonic()
    loop.stop()
    assert not loop.alive and time.monotonic() - t0 < SPIN_TIMEOUT_S
    assert loop.error is None


def test_a_guard_condition_is_refused_by_the_events_executor(ros, events_loop):
    node, loop = events_loop
    node.create_guard_condition(lambda: None)
    loop.start()
    assert ros.spin_until(lambda: not loop.alive, 5.0)
    assert "Guard conditions not supported" in str(loop.error)


def test_the_planes_resend_what_dds_could_not_deliver_on_every_service_they_serve(ros):
    """Planes.add hands every service of a node (its own and rclpy's parameter services) to
    LateResponses; the wrapped services answer over DDS as before."""
    saved = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    node = ros.rclpy.create_node("planes_test")

    def ping(_request, response):
        response.success = True
        return response
    node.create_service(Trigger, "~/ping", ping)
    server = ActionServer(node, WaitMotion, "~/wait", lambda goal: WaitMotion.Result())
    planes = Planes()
    try:
        planes.add("control", [node])
        assert isinstance(server._handle, UnlockedActionHandle)     # answers without the GIL
        senders = {s.service_name: s.send_response.__qualname__ for s in node.services}
        assert "/planes_test/ping" in senders and "/planes_test/list_parameters" in senders
        assert all(q.startswith("LateResponses._responder") for q in senders.values()), senders
        planes.start()
        assert ros.call(Trigger, "/planes_test/ping").success
    finally:
        planes.stop()
        node.destroy_node()
        for s, handler in saved.items():
            signal.signal(s, handler)


ARM_UP = (GetState, "/acti_middle_node/get_state")
BASE_UP = (VehicleGetState, "/vehicle_node/get_state")


@pytest.mark.parametrize("module, up, signum", [
    ("acti_bringup", ARM_UP, signal.SIGINT), ("acti_bringup", BASE_UP, signal.SIGTERM),
    ("acti_middle_node", ARM_UP, signal.SIGTERM), ("vehicle_node", BASE_UP, signal.SIGINT)])
def test_the_nodes_end_cleanly_on_a_signal(ros, tmp_path, module, up, signum):
    node = NodeProcess(module, str(tmp_path / "node.log"))
    try:
        assert wait_until(lambda: "services under" in node.log(), 60.0), node.log()
        ros.call(*up)                                   # serving
        node.proc.send_signal(signum)
        assert node.proc.wait(timeout=15.0) == 0, node.log()
    finally:
        node.stop()
    assert "Traceback" not in node.log(), node.log()


def test_goals_held_at_a_signal_end_aborted_and_their_clients_are_told(ros, tmp_path):
    """A client waiting for a goal's result when the job was stopped waited for ever: the
    goals died with the process unanswered (rclcpp ends a goal handle destroyed without an
    end; rclpy does not). Now every held goal ends aborted, saying why, before the job exits
    (a program's once the arm it stopped is at rest)."""
    from acti_msgs.action import Move, RunProgram, VehicleWaitMotion, WaitMotion
    from acti_msgs.srv import (ServoON, SetSpeedJoint, VehicleMoveForward, VehicleSetPower,
                               VehicleSetServo)
    from action_msgs.msg import GoalStatus
    from ros_harness import Actions
    node = NodeProcess("acti_bringup", str(tmp_path / "node.log"), "view_enabled:=false")
    try:
        assert wait_until(lambda: "services under" in node.log(), 60.0), node.log()
        ros.call(ServoON, "/acti_middle_node/servo_on")
        ros.call(SetSpeedJoint, "/acti_middle_node/set_speed_joint", spd_ratio=5)
        move = Actions(ros, Move, "/acti_middle_node/move")
        held = [move.send(kind=Move.Goal.PTP_JOINT_REL, joint_points=[90.0] + [0.0] * 6),
                Actions(ros, WaitMotion, "/acti_middle_node/wait_motion").send(motion_id=0)]
        ros.call(VehicleSetPower, "/vehicle_node/set_power", on_off=True)
        ros.call(VehicleSetServo, "/vehicle_node/set_servo", on_off=True)
        assert ros.call(VehicleMoveForward, "/vehicle_node/move_forward", x=5000.0).success
        held.append(Actions(ros, VehicleWaitMotion, "/vehicle_node/wait_motion").send())
        held.append(Actions(ros, RunProgram, "/acti_middle_node/run_program").send(
            text="Ar[R8 0 30 0 -60 0 60 0] ADRIVE DROP -1 $WAIT"))
        results = [h.get_result_async() for h in held]
        node.proc.send_signal(signal.SIGINT)
        assert node.proc.wait(timeout=15.0) == 0, node.log()
        assert ros.spin_until(lambda: all(r.done() for r in results), 5.0), node.log()
    finally:
        node.stop()
    arm, (base, program) = [r.result() for r in results[:2]], [r.result() for r in results[2:]]
    assert all(r.status == GoalStatus.STATUS_ABORTED for r in (*arm, base, program))
    assert all("shuts down" in r.result.return_id.comment for r in arm)
    assert "shuts down" in base.result.message and not base.result.completed
    assert "shuts down" in program.result.exception
    assert "Traceback" not in node.log(), node.log()


@pytest.mark.parametrize("domain", ["300", "-1", "seven"])
def test_a_domain_dds_cannot_use_is_one_line_and_exit_status_2(tmp_path, monkeypatch, domain):
    """Was: Fast DDS's own error ("Calculated port number is too high") and exit status 1."""
    monkeypatch.setenv("ROS_DOMAIN_ID", domain)
    node = NodeProcess("acti_bringup", str(tmp_path / "node.log"), "view_enabled:=false")
    try:
        assert node.proc.wait(timeout=60.0) == 2, node.log()
    finally:
        node.stop()
    fatal = [line for line in node.log().splitlines() if "[FATAL]" in line]
    assert len(fatal) == 1 and f"ROS_DOMAIN_ID={domain} is not a DDS domain: use 0 … 232" in fatal[0]
    assert "Traceback" not in node.log() and "RTPS" not in node.log(), node.log()


@pytest.mark.parametrize("module", ["acti_bringup", "vehicle_node"])
def test_help_prints_the_usage_and_starts_nothing(tmp_path, module):
    """`python -m acti_bringup --help` started a robot (and its live view) without a word."""
    node = NodeProcess(module, str(tmp_path / "node.log"), args=("--help",))
    try:
        assert node.proc.wait(timeout=30.0) == 0, node.log()
    finally:
        node.stop()
    assert f"python -m {module}" in node.log() and "--ros-args" in node.log()
    assert "services under" not in node.log(), node.log()
    assert "    queue_size: 32 [1 … 100000]  motion queue capacity" in node.log(), node.log()
    assert "    rate_hz: 250.0 [10 … 2000]  physics and control rate [Hz]" in node.log()
    assert "    allow_namesakes: False  start even where a node" in node.log()


def test_help_again_imports_no_simulation(tmp_path):
    """The list of parameters is made once (it builds the nodes out of sight) and kept: a
    second `--help` imports neither the simulation nor the motion core (it took 3-6 s)."""
    help_ = [sys.executable, "-X", "importtime", "-m", "vehicle_node", "--help"]
    subprocess.run(help_, capture_output=True, cwd=ROOT, check=True, timeout=120)
    again = subprocess.run(help_, capture_output=True, text=True, cwd=ROOT, check=True,
                           timeout=120)
    imported = {line.split("|")[-1].strip() for line in again.stderr.splitlines()}
    assert {"acti_sim", "acti_motion", "pybullet", "rclpy"}.isdisjoint(imported), imported
    assert "  vehicle_node:\n" in again.stdout


def test_nodes_of_one_name_are_one_line_and_exit_status_2(tmp_path):
    """`-r __node:=…` renames every node of the job: their services clashed with a traceback."""
    node = NodeProcess("acti_bringup", str(tmp_path / "node.log"), "view_enabled:=false",
                       args=("--ros-args", "-r", "__node:=acti_middle_node"))
    try:
        assert node.proc.wait(timeout=60.0) == 2, node.log()
    finally:
        node.stop()
    fatal = [line for line in node.log().splitlines() if "[FATAL]" in line]
    assert len(fatal) == 1 and "do two nodes of the process have one name?" in fatal[0]
    assert "Traceback" not in node.log(), node.log()


@pytest.mark.parametrize("module, param, namespace, words", [
    ("vehicle_node", "rate_hz:=-1.0", "", "rate_hz out of range"),
    ("acti_middle_node", "nice:=-30", "", "nice"),
    ("acti_bringup", "queue_size:=2.5", "", "queue_size"),
    ("vehicle_node", "velocity_min_translation:=-5.0", "", "velocity_min_translation out of range"),
    ("acti_bringup", "soft_limit_cartesian:=[0.0,1.0,0.0,1.0,0.0,.nan]", "",
     "soft_limit_cartesian = [0.0, 1.0, 0.0, 1.0, 0.0, nan]: it must be finite"),
    ("vehicle_node", "stuck_error:=.nan", "", "stuck_error out of range"),
    ("vehicle_node", "accel_limit_translation:=10.0", "", "would take 100 s"),
    ("acti_bringup", "initial_joints_deg:=[0.0,30.0,0.0,-60.0,0.0,.inf,0.0]", "",
     "initial_joints_deg = [0.0, 30.0, 0.0, -60.0, 0.0, inf, 0.0]: it must be finite"),
    ("acti_bringup", "view_host:=192.0.2.1", "", "is not an address of this machine"),
    # named alone (it listed every view rule with its value: "view_port … (is 8080)")
    ("acti_bringup", "acti_view:view_rate_hz:=0.0", "", "view_rate_hz out of range"),
    ("acti_bringup", "rate_hz:=250.0", "/robot-1", "Couldn't parse remap rule"),
    ("vehicle_node", "world:=/no/such/world.yaml", "",
     "world file /no/such/world.yaml: the file: No such file or directory")])
def test_a_refused_start_up_setting_is_one_line_and_exit_status_2(tmp_path, module, param,
                                                                  namespace, words):
    """Was: a traceback (and exit status 1) for a value out of range or of the wrong type, or a
    namespace rcl cannot parse."""
    node = NodeProcess(module, str(tmp_path / "node.log"), param, namespace=namespace)
    try:
        assert node.proc.wait(timeout=60.0) == 2, node.log()
    finally:
        node.stop()
    log = node.log()
    fatal = [line for line in log.splitlines() if "[FATAL]" in line]
    assert len(fatal) == 1 and f"[{module}]: cannot start:" in fatal[0] and words in fatal[0], log
    assert "Traceback" not in log, log


def test_a_busy_client_keeps_its_answer_among_answers_to_other_clients(ros, events_loop):
    """DDS hands every response of a service to every client of it. A client that does not take
    while another client gets 30 answers loses its own with rclpy's history of 10, and keeps it
    with the harness's (CLIENT_QOS): why a storm of clients cost a busy client its answer."""
    from rclpy.executors import SingleThreadedExecutor
    node, loop = events_loop

    def ping(_request, response):
        response.success = True
        return response
    node.create_service(Trigger, "~/ping", ping)
    loop.start()
    name = "/spin_loop_test/ping"
    kept = ros.node.create_client(Trigger, name, qos_profile=ros.client_qos)
    shallow = ros.node.create_client(Trigger, name)
    other = ros.rclpy.create_node("other_client")
    others = SingleThreadedExecutor()
    others.add_node(other)
    busy = other.create_client(Trigger, name)
    try:
        assert all(c.wait_for_service(timeout_sec=30.0) for c in (kept, shallow, busy))
        mine = [kept.call_async(Trigger.Request()), shallow.call_async(Trigger.Request())]
        for _ in range(30):                    # answered while the test client does not take
            future = busy.call_async(Trigger.Request())
            others.spin_until_future_complete(future, timeout_sec=10.0)
            assert future.done()
        assert ros.spin_until(lambda: mine[0].done(), 10.0) and mine[0].result().success
        assert not ros.spin_until(lambda: mine[1].done(), 1.0)
    finally:
        others.shutdown()
        for client in (kept, shallow):
            ros.node.destroy_client(client)
        other.destroy_node()
