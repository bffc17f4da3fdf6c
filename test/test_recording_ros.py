"""Recording and replaying the job over DDS: the README's quick tour, pasted as it is, recorded
by the job's own `record` parameter and its calls replayed against a fresh job with every
answer equal; topics read back with rosbags as they were published and republished with their
timing; a recorder killed with -9 while both devices move leaves a file that reads up to its
last flush and is reindexed whole for rosbags; what is not a recording is refused in one line."""
import os
import signal
import subprocess
import sys

import pytest
from mcap.reader import make_reader
from rclpy.serialization import deserialize_message
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_typestore
from std_msgs.msg import String

from acti_bringup.harness import (ROOT, NodeProcess, both_moving, keep_moving, start_moving,
                                  wait_until)
from acti_bringup.recording.replay import recorded_calls
from acti_record.reading import BadRecording, read_recording
from ros_harness import TEST_RATE
from test_readme_tour import bounded, pasted_tour, run_pasted

LASTING = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)


def job(tmp_path, name: str, *params: str) -> NodeProcess:
    return NodeProcess("acti_bringup", str(tmp_path / f"{name}.log"), TEST_RATE,
                       "view_enabled:=false", *params)


def run(module: str, *args: str, timeout: float = 240.0) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", module, *args], cwd=ROOT, capture_output=True,
                          text=True, timeout=timeout)


def recorder(path: str, *topics: str) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "acti_bringup.record", path, *topics],
                            cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)



@pytest.fixture(scope="module")
def recorded_tour(tmp_path_factory):
    """The README's quick tour pasted as it is (the jog bounded as test_readme_tour bounds it,
    sent once the job and its recorder both listen) on a job at real time that records itself;
    the job then stopped with Ctrl-C. (the file, what the tour printed, the folder)"""
    folder = tmp_path_factory.mktemp("tour")
    path = str(folder / "tour.mcap")
    first = job(folder, "first", "real_time_factor:=1.0", f"record:={path}")
    try:
        printed = run_pasted("\n".join(bounded(c.text, listeners=2) for c in pasted_tour()))
    finally:
        stopped = first.stop()
    assert stopped in (0, -signal.SIGINT) and "Traceback" not in first.log(), first.log()
    return path, printed, folder


def test_the_quick_tour_is_recorded_call_by_call(recorded_tour):
    path, printed, _ = recorded_tour
    calls = [c.service for c in recorded_calls(read_recording(path))]
    assert len(calls) == printed.count("requester: making request") + 2 * printed.count(
        "Sending goal"), (calls, printed)      # a goal: its goal and its result


def test_the_recorded_tour_replayed_against_a_fresh_job_answers_every_call_equally(
        recorded_tour):
    path, _, folder = recorded_tour
    fresh = job(folder, "fresh", "real_time_factor:=1.0")
    try:
        replayed = run("acti_bringup.replay", path, "--requests")
    finally:
        fresh.stop()
    out = replayed.stdout + replayed.stderr
    print(out)                                  # the timing and the allowances used (-s)
    assert replayed.returncode == 0, out
    calls = int(out.split(" calls, ")[0].rsplit("\n", 1)[-1])
    assert out.rstrip().endswith(f"{calls} calls, 0 differences"), out
    assert out.count(": equal") == calls, out       # every answer was compared


def test_topics_read_back_with_rosbags_as_published_and_are_republished(ros, tmp_path):
    path = str(tmp_path / "topics.mcap")
    sent = [f"message {i}: " + "x" * (i % 50) for i in range(300)]
    rec = recorder(path, "/record_test")
    # transient local: the recorder gets them all, however late it matches (as rosbag2 would)
    publisher = ros.node.create_publisher(String, "/record_test", LASTING)
    try:
        for text in sent:
            publisher.publish(String(data=text))
        assert wait_until(lambda: len(_flushed(path)) == len(sent), 60.0), _flushed(path)
    finally:
        rec.send_signal(signal.SIGINT)
        assert rec.wait(timeout=30) == 0
        ros.node.destroy_publisher(publisher)
    assert f"recorded {len(sent)} messages" in rec.stdout.read()
    with AnyReader([tmp_path / "topics.mcap"],
                   default_typestore=get_typestore(Stores.ROS2_JAZZY)) as bag:
        (connection,) = bag.connections
        assert (connection.topic, connection.msgtype) == ("/record_test", "std_msgs/msg/String")
        read = [bag.deserialize(raw, c.msgtype).data for c, _, raw in bag.messages()]
    assert read == sent

    received = []
    subscription = ros.node.create_subscription(String, "/record_test",
                                                lambda m: received.append(m.data), LASTING)
    replay = subprocess.Popen([sys.executable, "-m", "acti_bringup.replay", path, "--rate", "2",
                               "--wait-for-subscribers", "30"],
                              cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        assert ros.spin_until(lambda: replay.poll() is not None and len(received) >= len(sent),
                              60.0), (replay.poll(), len(received))
    finally:
        replay.kill()
        ros.node.destroy_subscription(subscription)
    assert replay.wait() == 0 and received == sent, replay.stdout.read()


def _flushed(path: str):
    """What the file holds so far (the recorder flushes every second)."""
    try:
        return read_recording(path).messages
    except BadRecording:            # not there yet, or no chunk yet
        return []



def test_a_recorder_killed_with_9_while_both_devices_move_leaves_a_file_reindexed_whole(
        ros, tmp_path):
    """What the file held when the kill came is all read back, by rosbags once reindexed (what
    is lost came after the recorder's last flush); the next recording to the same file keeps
    it under another name."""
    moving = job(tmp_path, "moving")
    path = str(tmp_path / "killed.mcap")
    rec = recorder(path)                     # every topic: the job's clock, joints, TF …
    sent = [f"sent before the kill {i}" for i in range(200)]
    publisher = ros.node.create_publisher(String, "/record_kill_test", LASTING)
    try:
        start_moving(ros)
        keep_moving(ros, 12)
        for text in sent:
            publisher.publish(String(data=text))
        assert wait_until(lambda: os.path.exists(path) and os.path.getsize(path) > 1_000_000
                          and _texts(_flushed(path)) == sent, 120.0), rec
        assert both_moving(ros)
        held = read_recording(path).messages  # the file as the kill finds it, at least
    finally:
        rec.kill()
        rec.wait()
        ros.node.destroy_publisher(publisher)
        moving.stop()
    contents = read_recording(path)
    assert "ends early" in contents.problem and "acti_bringup.reindex" in contents.problem
    assert [m.data for m in contents.messages[:len(held)]] == [m.data for m in held]
    shown = run("acti_bringup.replay", path, "--topics", "/none")   # reads it, says what is lost
    assert shown.returncode == 0 and "ends early" in shown.stderr, shown.stdout + shown.stderr

    listed = os.listdir(tmp_path)
    again = recorder(path, "/none")          # the next session to the same file keeps this one
    try:
        assert wait_until(lambda: len(os.listdir(tmp_path)) > len(listed), 60.0)
    finally:
        again.send_signal(signal.SIGINT)
        assert again.wait(timeout=30) == 0
    (kept,) = [tmp_path / f for f in os.listdir(tmp_path) if f.startswith("killed-")]
    assert f"{path} was cut short (its recorder killed): kept as {kept}" in again.stdout.read()
    path = str(kept)

    reindexed = run("acti_bringup.reindex", path)
    assert reindexed.returncode == 0 and reindexed.stdout.startswith(f"reindexed {path} ("), \
        reindexed.stdout + reindexed.stderr
    with AnyReader([kept], default_typestore=get_typestore(Stores.ROS2_JAZZY)) as bag:
        read = [(c.topic, raw) for c, _, raw in bag.messages()]
        joints = [bag.deserialize(raw, c.msgtype) for c, _, raw in bag.messages()
                  if c.topic == "/joint_states"]
        texts = [bag.deserialize(raw, c.msgtype).data for c, _, raw in bag.messages()
                 if c.topic == "/record_kill_test"]
    assert sorted(raw for _, raw in read) == sorted(m.data for m in contents.messages)
    assert {"/clock", "/joint_states", "/tf"} <= {topic for topic, _ in read}
    assert texts == sent
    first, last = joints[0], joints[-1]    # the joints moved while it recorded
    assert [round(p, 3) for p in first.position] != [round(p, 3) for p in last.position]
    with open(path, "rb") as f:
        assert make_reader(f).get_summary().statistics.message_count == len(contents.messages)
    assert run("acti_bringup.reindex", path).stdout.endswith("left alone\n")


def _texts(messages) -> list[str]:
    return [deserialize_message(m.data, String).data for m in messages
            if m.channel.topic == "/record_kill_test"]


@pytest.mark.parametrize("content", [b"", b"plain text, not a recording\n", b"\x89MCAP0\r\n\x01"])
def test_what_is_not_a_recording_is_refused_with_one_line(tmp_path, content):
    bad = tmp_path / "bad.mcap"
    bad.write_bytes(content)
    for args in ([str(bad)], [str(bad), "--requests"], [str(tmp_path / "missing.mcap")]):
        refused = run("acti_bringup.replay", *args, timeout=60)
        assert refused.returncode == 2 and refused.stdout == "", refused
        assert refused.stderr.count("\n") == 1 and "Traceback" not in refused.stderr


def test_an_unknown_introspection_setting_stops_the_job_with_one_line(tmp_path):
    refused = run("acti_bringup", "--ros-args", "-p", "service_introspection:=everything",
                  "-p", "view_enabled:=false", timeout=120)
    out = refused.stdout + refused.stderr
    assert refused.returncode == 2 and "Traceback" not in out, out
    assert "service_introspection is 'everything': use one of disabled, metadata, contents" in out


def test_sigterm_ends_a_recording_with_a_complete_file(tmp_path):
    path = str(tmp_path / "term.mcap")
    rec = recorder(path, "/nothing_here")
    try:
        assert wait_until(lambda: os.path.exists(path), 60.0)
        assert rec.poll() is None
    finally:
        rec.send_signal(signal.SIGTERM)
        code = rec.wait(timeout=30)
    assert code == 0 and "recorded 0 messages" in rec.stdout.read()
    with open(path, "rb") as f:                        # summary and footer written
        reader = make_reader(f)
        assert reader.get_summary() is not None
        assert [m.name for m in reader.iter_metadata()] == ["rosbag2"]
