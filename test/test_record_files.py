"""The ROS-free recording core: files as rosbag2 writes them (read back by rosbags and by the
mcap library's own indexed reader), split files, files cut short by a kill, files that are not
recordings at all."""
import os
import shutil

import pytest
from mcap.reader import make_reader
from rclpy.serialization import serialize_message
from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_typestore
from std_msgs.msg import String

from acti_bringup.recording.types import share_dir
from acti_record.definitions import SEPARATOR, full_text
from acti_record.reading import BadRecording, read_recording
from acti_record.writing import McapFile, Recording, Topic, qos_profile

INFINITE_NS = 9223372036854775807
RELIABLE = qos_profile("keep_last", 10, "reliable", "volatile", INFINITE_NS, INFINITE_NS,
                       "automatic", INFINITE_NS)
STRING = Topic("/chatter", "std_msgs/msg/String", full_text("std_msgs/msg/String", share_dir),
               (RELIABLE,), "RIHS01_" + "ab" * 32)


def strings(count: int, size: int = 10) -> list[bytes]:
    return [serialize_message(String(data=f"{i:06d}" + "x" * size)) for i in range(count)]


def write(recording, data: list[bytes], t0: int = 1_000_000_000) -> None:
    for i, d in enumerate(data):
        recording.write(STRING, d, t0 + i * 1_000_000, t0 + i * 1_000_000)


def test_a_definition_holds_every_type_it_uses_once_after_rosbag2s_delimiter():
    text = full_text("sensor_msgs/msg/JointState", share_dir)
    assert text.startswith("#") and "std_msgs/Header header" in text
    for used in ("std_msgs/msg/Header", "builtin_interfaces/msg/Time"):
        assert text.count(f"{SEPARATOR}\nMSG: {used}\n") == 1


def test_a_service_event_and_an_action_feedback_get_their_generated_shapes():
    event = full_text("acti_msgs/srv/ServoON_Event", share_dir)
    assert event.startswith("service_msgs/msg/ServiceEventInfo info\n"
                            "acti_msgs/srv/ServoON_Request[<=1] request\n")
    assert "MSG: acti_msgs/srv/ServoON_Response\nReturnId return_id" in event
    assert "MSG: acti_msgs/msg/ReturnId\n" in event
    goal = full_text("acti_msgs/action/Move_SendGoal_Event", share_dir)
    assert "MSG: acti_msgs/action/Move_Goal\n" in goal and "MSG: unique_identifier_msgs/msg/UUID" in goal
    feedback = full_text("acti_msgs/action/Move_FeedbackMessage", share_dir)
    assert "MSG: acti_msgs/action/Move_Feedback\n" in feedback and "uint32 motion_id" in feedback


def test_a_file_reads_back_as_written_with_rosbag2s_metadata(tmp_path):
    path = str(tmp_path / "a.mcap")
    data = strings(50)
    recording = Recording(path)
    write(recording, data)
    recording.close()
    assert [m.data for m in read_recording(path).messages] == data
    with open(path, "rb") as f:          # the summary an indexed reader uses
        reader = make_reader(f)
        header, summary = reader.get_header(), reader.get_summary()
        assert header.profile == "ros2"
        (schema,), (channel,) = summary.schemas.values(), summary.channels.values()
        assert (schema.name, schema.encoding) == ("std_msgs/msg/String", "ros2msg")
        assert channel.message_encoding == "cdr"
        assert set(channel.metadata) == {"offered_qos_profiles", "topic_type_hash"}
        assert "reliability: reliable" in channel.metadata["offered_qos_profiles"]
        assert summary.statistics.message_count == 50
        assert "rosbag2" in {m.name for m in reader.iter_metadata()}
    with AnyReader([tmp_path / "a.mcap"],
                   default_typestore=get_typestore(Stores.ROS2_JAZZY)) as bag:
        read = [bag.deserialize(raw, c.msgtype).data for c, _, raw in bag.messages()]
    assert read == [f"{i:06d}" + "x" * 10 for i in range(50)]


def test_a_size_limit_splits_the_recording_into_numbered_files(tmp_path):
    path = str(tmp_path / "s.mcap")
    data = strings(400, size=2000)
    recording = Recording(path, max_bytes=300_000)
    for i, d in enumerate(data):
        write(recording, [d], t0=1_000_000_000 + i)
        if i % 50 == 0:
            recording.flush()
    recording.close()
    assert len(recording.paths) > 1
    assert recording.paths[0].endswith("s_0.mcap") and all(map(os.path.exists, recording.paths))
    assert [m.data for m in read_recording(path).messages] == data   # found by stem


def test_a_file_cut_short_gives_its_complete_chunks_and_says_what_was_lost(tmp_path):
    whole = str(tmp_path / "whole.mcap")
    data = strings(3000, size=200)
    file = McapFile(whole, chunk_bytes=20_000)
    for i, d in enumerate(data):
        file.write(STRING, d, i, i)
    file.close()
    cut = str(tmp_path / "cut.mcap")
    size = os.path.getsize(whole)
    with open(whole, "rb") as src, open(cut, "wb") as dst:
        dst.write(src.read(size // 2))
    contents = read_recording(cut)
    assert "ends early" in contents.problem and "last chunk is lost" in contents.problem
    read = [m.data for m in contents.messages]
    assert len(read) > 1000 and read == data[:len(read)]


@pytest.mark.parametrize("content, says", [
    (b"", "not an MCAP recording"),
    (b"not a recording at all, just text\n" * 10, "not an MCAP recording"),
    (b"\x89MCAP0\r\n", "without a complete chunk"),
    (b"\x89MCAP0\r\n" + b"\xff" * 100, "without a complete chunk"),
])
def test_what_is_not_a_recording_is_refused_in_one_line(tmp_path, content, says):
    path = tmp_path / "bad.mcap"
    path.write_bytes(content)
    with pytest.raises(BadRecording, match=says) as refused:
        read_recording(str(path))
    assert "\n" not in str(refused.value)


def test_a_missing_recording_is_refused_in_one_line(tmp_path):
    with pytest.raises(BadRecording, match="no such recording"):
        read_recording(str(tmp_path / "none.mcap"))
