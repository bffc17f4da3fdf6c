"""tools/ros2_lite.py (the bundled `ros2`) fills requests and prints what the real `ros2` CLI does."""
import importlib.util
import os
import re
import signal
import subprocess
import sys

import pytest
import yaml
from acti_msgs.srv import VehicleGetState

from acti_bringup.harness import ROOT
from ros_harness import node_fixture

sys.path.insert(0, os.path.join(ROOT, "tools"))      # its modules beside it
_spec = importlib.util.spec_from_file_location("ros2_lite",
                                               os.path.join(ROOT, "tools", "ros2_lite.py"))
ros2_lite = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(ros2_lite)


def test_a_request_is_filled_from_yaml_with_integers_for_floats():
    cls = ros2_lite.interface("acti_msgs/srv/VehicleMoveLinearAbs")
    req = ros2_lite.request(cls.Request, "{pos: {x: 1000, y: 500.5, theta: 0}}")
    assert (req.pos.x, req.pos.y, req.pos.theta) == (1000.0, 500.5, 0.0)
    joints = ros2_lite.request(ros2_lite.interface("acti_msgs/srv/MovePTPJointAbs").Request,
                               "{joint_points: [10, 20.5]}")
    assert list(joints.joint_points) == [10.0, 20.5]


def test_a_sequence_of_messages_is_filled_item_by_item():
    twist = ros2_lite.request(ros2_lite.interface("geometry_msgs/msg/Twist"),
                              "{linear: {x: 0.2}, angular: {z: 0.3}}")
    assert (twist.linear.x, twist.angular.z) == (0.2, 0.3)
    event = ros2_lite.request(ros2_lite.interface("rcl_interfaces/msg/ParameterEvent"),
                              "{node: /n, new_parameters: [{name: a}, {name: b}]}")
    assert [p.name for p in event.new_parameters] == ["a", "b"]
    assert ros2_lite.as_plain(event)["new_parameters"][1]["name"] == "b"


@pytest.mark.parametrize("type_name, values, why", [
    ("acti_msgs/srv/VehicleMoveForward", "{y: 1.0}", "has no field 'y'"),
    ("acti_msgs/srv/VehicleMoveForward", "{x: fast}", "cannot be 'fast'"),
    ("acti_msgs/srv/VehicleMoveForward", "[1, 2]", "must be a mapping"),
    ("acti_msgs/srv/VehicleMoveForward", "{x: [1", "not YAML"),
    ("acti_msgs/srv/MovePTPJointAbs", "{joint_points: 3}", "is a sequence"),
    ("acti_msgs/srv/NoSuchThing", "{}", "not known here"),
    ("acti_msgs/NoSuchThing", "{}", "must be pkg/msg|srv|action/Name"),
])
def test_what_cannot_be_sent_is_one_line_that_says_why(type_name, values, why):
    with pytest.raises(ros2_lite.Usage, match=why.replace("|", r"\|").replace("[", r"\[")):
        cls = ros2_lite.interface(type_name)
        ros2_lite.request(cls.Request, values)


# --- the commands, as the real CLI prints them (ros2cli jazzy) -----------------------------------
ROS2 = os.path.join(ROOT, "tools", "bin", "ros2")


def ros2(*args: str, timeout: float = 120) -> subprocess.CompletedProcess:
    return subprocess.run([ROS2, *args], capture_output=True, text=True, timeout=timeout)


def test_interface_show_prints_the_file_and_each_nested_definition_a_tab_further_in():
    shown = ros2("interface", "show", "geometry_msgs/msg/PoseStamped").stdout
    assert shown.startswith("# A Pose with reference coordinate frame and timestamp\n\n"
                            "std_msgs/Header header\n\tbuiltin_interfaces/Time stamp\n"
                            "\t\tint32 sec\n"), shown
    assert "Pose pose\n\tPoint position\n\t\tfloat64 x\n" in shown
    bare = ros2("interface", "show", "--no-comments", "acti_msgs/srv/VehicleGetState").stdout
    assert "#" not in bare and "\n\n" not in bare and "---\n" in bare, bare


def test_interface_list_and_package_name_every_interface_of_the_index():
    listed = ros2("interface", "list").stdout
    assert listed.index("Messages:") < listed.index("Services:") < listed.index("Actions:")
    assert "    acti_msgs/srv/VehicleGetState\n" in listed
    assert "    acti_msgs/action/RunProgram\n" in listed
    package = ros2("interface", "package", "acti_msgs").stdout.splitlines()
    own = sorted(f"acti_msgs/{kind}/{name[:-len(kind) - 1]}" for kind in ("msg", "srv", "action")
                 for name in os.listdir(os.path.join(ROOT, "msg_defs", kind)))
    assert package == own
    only = ros2("interface", "package", "-a", "acti_msgs").stdout.splitlines()
    assert only and all(line.startswith("acti_msgs/action/") for line in only)


@pytest.mark.parametrize("args, said", [
    (("interface", "show", "acti_msgs/srv/NoSuch"), "Could not find the interface"),
    (("interface", "package", "no_such_msgs"), "Unknown package 'no_such_msgs'"),
])
def test_an_unknown_interface_is_one_line_and_status_1(args, said):
    done = ros2(*args)
    assert done.returncode == 1 and said in done.stderr and "Traceback" not in done.stderr


vehicle = node_fixture("vehicle_node")


def _answers(commands: dict[str, tuple[str, ...]]) -> dict[str, subprocess.CompletedProcess]:
    """Each command run at once beside the others (each waits a few seconds for discovery)."""
    started = {key: subprocess.Popen([ROS2, *args], stdout=subprocess.PIPE,
                                     stderr=subprocess.PIPE, text=True)
               for key, args in commands.items()}
    done = {}
    for key, proc in started.items():
        out, err = proc.communicate(timeout=120)
        done[key] = subprocess.CompletedProcess(proc.args, proc.returncode, out, err)
    return done


def test_the_graph_commands_print_what_the_real_cli_prints_and_hide_the_hidden(vehicle, ros):
    ros.call(VehicleGetState, "/vehicle_node/get_state")          # it serves
    got = _answers({
        "nodes": ("node", "list"), "all nodes": ("node", "list", "-a"),
        "info": ("node", "info", "/vehicle_node"),
        "topics": ("topic", "list", "-t"), "all topics": ("topic", "list", "--include-hidden"),
        "topic type": ("topic", "type", "/vehicle_node/state"),
        "topic info": ("topic", "info", "/vehicle_node/state"),
        "hz": ("topic", "hz", "--times", "1", "/vehicle_node/state"),
        "services": ("service", "list"),
        "service type": ("service", "type", "/vehicle_node/get_state"),
        "find": ("service", "find", "acti_msgs/srv/VehicleGetState"),
        "actions": ("action", "list", "-t"),
        "action info": ("action", "info", "/vehicle_node/wait_motion"),
        "dump": ("param", "dump", "/vehicle_node"),
        "no node": ("node", "info", "/no_such_node"),
    })
    for key, done in got.items():
        assert "Traceback" not in done.stderr, f"{key}: {done.stderr}"
    nodes = got["nodes"].stdout.splitlines()
    assert "/vehicle_node" in nodes and not any("/_" in n for n in nodes), nodes
    assert "/_vehicle_node_goals" in got["all nodes"].stdout.splitlines()
    info = got["info"].stdout
    assert info.startswith("/vehicle_node\n  Subscribers:\n"), info
    assert "  Publishers:\n" in info and "    /vehicle_node/state: acti_msgs/msg/VehicleStatus\n" in info
    assert "    /vehicle_node/get_state: acti_msgs/srv/VehicleGetState\n" in info
    assert "_action" not in info and "  Action Clients:\n" in info
    assert "/vehicle_node/state [acti_msgs/msg/VehicleStatus]" in got["topics"].stdout
    assert "_action" not in got["topics"].stdout
    assert "/vehicle_node/wait_motion/_action/status" in got["all topics"].stdout
    assert got["topic type"].stdout == "acti_msgs/msg/VehicleStatus\n"
    assert got["topic info"].stdout.startswith("Type: acti_msgs/msg/VehicleStatus\n"
                                               "Publisher count: 1\nSubscription count: ")
    assert re.fullmatch(r"average rate: \d+\.\d{3}\n\tmin: \d+\.\d{3}s max: \d+\.\d{3}s "
                        r"std dev: \d+\.\d{5}s window: \d+\n", got["hz"].stdout), got["hz"].stdout
    services = got["services"].stdout.splitlines()
    assert "/vehicle_node/get_state" in services and not any("_action" in s for s in services)
    assert got["service type"].stdout == "acti_msgs/srv/VehicleGetState\n"
    found = got["find"].stdout.splitlines()     # (a fleet test's robots can linger in the graph)
    assert "/vehicle_node/get_state" in found and all(
        s.endswith("/vehicle_node/get_state") for s in found), found
    assert "/vehicle_node/wait_motion [acti_msgs/action/VehicleWaitMotion]" in got["actions"].stdout
    action = got["action info"].stdout          # (the suite's own clients come and go)
    assert action.startswith("Action: /vehicle_node/wait_motion\nAction clients: ")
    assert action.endswith("\nAction servers: 1\n    /_vehicle_node_goals\n"), action
    dumped = yaml.safe_load(got["dump"].stdout)
    assert dumped["/vehicle_node"]["ros__parameters"]["max_wait_goals"] == 16
    assert got["no node"].returncode == 1
    assert got["no node"].stderr == "Unable to find node '/no_such_node'\n"


def test_a_node_that_left_the_graph_since_it_was_listed_has_no_endpoints(ros):
    """`action info` and `node info` list the nodes, then ask each for its endpoints: a node
    gone meanwhile (the suite's clients come and go) made rcl fail and the command print a
    traceback (CI at f0c27e9). Asked for a node that is not there, rcl fails the same way."""
    import ros2_graph
    from rclpy.action.graph import (get_action_client_names_and_types_by_node,
                                    get_action_server_names_and_types_by_node)
    node = ros.node
    for query in (get_action_client_names_and_types_by_node,
                  get_action_server_names_and_types_by_node):
        assert ros2_graph.of_node(query, node, "no_such_node", "/") == []
    for query in (node.get_publisher_names_and_types_by_node,
                  node.get_service_names_and_types_by_node):
        assert ros2_graph.of_node(query, "no_such_node", "/") == []


@pytest.mark.parametrize("sig, status", [(signal.SIGINT, 2), (signal.SIGTERM, 15)])
def test_a_signal_ends_an_endless_command_without_a_traceback(vehicle, ros, sig, status):
    ros.call(VehicleGetState, "/vehicle_node/get_state")
    echo = subprocess.Popen([ROS2, "topic", "echo", "/vehicle_node/state"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert echo.stdout.readline()            # it echoes
    echo.send_signal(sig)
    out, err = echo.communicate(timeout=60)
    assert echo.returncode == status and "Traceback" not in err, err
