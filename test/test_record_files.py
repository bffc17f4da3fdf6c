"""The ROS-free recording core: files as rosbag2 writes them (read back by rosbags and by the
mcap library's own indexed reader), split files, files cut short by a kill and reindexed whole,
files that are not recordings at all."""
import os
import shutil
import subprocess
import sys

from pathlib import Path

import pytest
from mcap.reader import make_reader
from mcap.records import Footer
from mcap.stream_reader import StreamReader
from rclpy.serialization import serialize_message
from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_typestore
from std_msgs.msg import String

from acti_bringup.recording.types import share_dir
from acti_record.definitions import SEPARATOR, full_text
from acti_record.reading import REINDEX_COMMAND, BadRecording, read_recording
from acti_record.reindexing import reindex_file
from acti_record.writing import McapFile, RecordedElsewhere, Recording, Topic, qos_profile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

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
    assert f"{REINDEX_COMMAND} {cut}` rewrites it whole" in contents.problem
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


def whole_file(path: str, count: int = 3000, compression: str = "none") -> list[bytes]:
    """A complete file of `count` strings in many small chunks, log time i, sequence i."""
    data = strings(count, size=200)
    file = McapFile(path, compression, chunk_bytes=20_000)
    channel = file.channel(STRING)
    for i, d in enumerate(data):
        file.write_to(channel, STRING.name, d, 1_000 + i, 2_000 + i, sequence=i)
    file.close()
    return data


def cut_copy(whole: str, to: str, size: int) -> str:
    with open(whole, "rb") as src, open(to, "wb") as dst:
        dst.write(src.read(size))
    return to


def kept_before(summary, cut: int) -> int:
    """How many messages are in the chunks that end before `cut` (log times 1000, 1001 …)."""
    ends = [c.message_end_time for c in summary.chunk_indexes
            if c.chunk_start_offset + c.chunk_length <= cut]
    return max(ends) - 1_000 + 1 if ends else 0


def opened_by_its_summary(path: str):
    """What readers that need the summary read: mcap's indexed reader (summary, messages,
    the rosbag2 record) and rosbags' AnyReader (the strings)."""
    with open(path, "rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        assert summary is not None
        messages = [(m.log_time, m.publish_time, m.sequence, m.data)
                    for _, _, m in reader.iter_messages(log_time_order=False)]
        (bag,) = [m for m in reader.iter_metadata() if m.name == "rosbag2"]
    with AnyReader([Path(path)], default_typestore=get_typestore(Stores.ROS2_JAZZY)) as rosbag:
        texts = [rosbag.deserialize(raw, c.msgtype).data for c, _, raw in rosbag.messages()]
    return summary, messages, bag.metadata["serialized_metadata"], texts


def test_a_file_cut_short_is_refused_by_readers_that_need_its_summary(tmp_path):
    whole = str(tmp_path / "whole.mcap")
    whole_file(whole)
    cut = cut_copy(whole, str(tmp_path / "cut.mcap"), os.path.getsize(whole) // 2)
    with pytest.raises(Exception, match="magic"):
        with AnyReader([Path(cut)], default_typestore=get_typestore(Stores.ROS2_JAZZY)):
            pass
    with open(cut, "rb") as f, pytest.raises(Exception):
        make_reader(f).get_summary()


def cut_offsets(whole: str) -> dict[str, int]:
    """Where a kill can cut a file: mid-chunk (many), at a chunk's end, between a chunk and
    its message indexes, at the data section's end, mid-summary, in the footer and magic."""
    with open(whole, "rb") as f:
        summary = make_reader(f).get_summary()
        f.seek(0)
        (footer,) = [r for r in StreamReader(f).records if isinstance(r, Footer)]
    summary_start = footer.summary_start
    chunks = summary.chunk_indexes
    first = chunks[0]
    size = os.path.getsize(whole)
    offsets = {f"mid-chunk {i}": c.chunk_start_offset + c.chunk_length // 3
               for i, c in enumerate(chunks) if i % 7 == 1}
    offsets.update({
        "the first chunk's end": first.chunk_start_offset + first.chunk_length,
        "in the first chunk's message index": first.chunk_start_offset + first.chunk_length + 5,
        "after the last chunk's indexes": chunks[-1].chunk_start_offset + chunks[-1].chunk_length
        + chunks[-1].message_index_length,
        "the data section's end": summary_start,
        "mid-summary": (summary_start + size) // 2,
        "in the footer": size - 15,
        "in the closing magic": size - 3})
    return offsets


@pytest.mark.parametrize("compression", ["none", "zstd"])
def test_a_file_cut_anywhere_is_reindexed_whole_and_opens_with_rosbags_and_mcap(tmp_path,
                                                                               compression):
    whole = str(tmp_path / "whole.mcap")
    data = whole_file(whole, compression=compression)
    with open(whole, "rb") as f:
        original = make_reader(f).get_summary()
    (channel,) = original.channels.values()
    for where, offset in cut_offsets(whole).items():
        cut = cut_copy(whole, str(tmp_path / "cut.mcap"), offset)
        done = reindex_file(cut)
        kept = min(kept_before(original, offset), len(data))
        assert done.messages == kept and done.lost, where
        summary, messages, bag, texts = opened_by_its_summary(cut)
        assert messages == [(1_000 + i, 2_000 + i, i, data[i]) for i in range(kept)], where
        assert texts == [f"{i:06d}" + "x" * 200 for i in range(kept)], where
        assert summary.statistics.message_count == kept, where
        assert f"message_count: {kept}\n" in bag and "relative_file_paths:\n- cut.mcap" in bag
        (again,) = summary.channels.values()
        assert (again.topic, again.metadata) == (channel.topic, channel.metadata), where
        (schema,) = summary.schemas.values()
        assert (schema.name, schema.encoding, schema.data) == (
            "std_msgs/msg/String", "ros2msg", original.schemas[channel.schema_id].data)
        assert {c.compression for c in summary.chunk_indexes} == {
            "" if compression == "none" else compression}, where
        assert not read_recording(cut).problem
        assert not [p for p in os.listdir(tmp_path) if p.endswith(".reindexing")]


def test_a_complete_file_is_left_alone(tmp_path):
    whole = str(tmp_path / "whole.mcap")
    whole_file(whole, count=100)
    before = (open(whole, "rb").read(), os.stat(whole).st_mtime_ns)
    done = reindex_file(whole)
    assert (done.messages, done.lost) == (100, "") and "already complete" in done.text
    assert (open(whole, "rb").read(), os.stat(whole).st_mtime_ns) == before


def test_a_file_being_recorded_is_not_reindexed(tmp_path):
    path = str(tmp_path / "live.mcap")
    recording = Recording(path)
    write(recording, strings(10))
    recording.flush()
    with pytest.raises(RecordedElsewhere, match="being recorded"):
        reindex_file(path)
    with pytest.raises(RecordedElsewhere, match="being recorded"):
        Recording(path)                  # nor emptied by a second recorder
    recording.close()
    assert len(read_recording(path).messages) == 10


def reindex(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "acti_bringup.reindex", *args], cwd=ROOT,
                          capture_output=True, text=True, timeout=120)


def test_the_command_reindexes_the_split_files_of_a_stem_cut_short(tmp_path):
    stem = str(tmp_path / "s.mcap")
    recording = Recording(stem, max_bytes=300_000)
    data = strings(400, size=2000)
    for i, d in enumerate(data):
        write(recording, [d], t0=1_000_000_000 + i)
        if i % 50 == 0:
            recording.flush()
    recording.flush()                    # killed here: the last file has no summary
    last = recording.paths[-1]
    shutil.copy(last, str(tmp_path / "cut"))
    recording.close()
    os.replace(str(tmp_path / "cut"), last)
    done = reindex(stem)
    assert done.returncode == 0 and done.stderr == "", done
    lines = done.stdout.splitlines()
    assert len(lines) == len(recording.paths) and lines[-1].startswith(f"reindexed {last} (")
    assert all("already complete" in line for line in lines[:-1]), lines
    texts = []
    for path in recording.paths:
        texts += opened_by_its_summary(path)[3]
    assert [serialize_message(String(data=t)) for t in texts] == data


@pytest.mark.parametrize("content, says", [
    (b"not a recording at all, just text\n" * 10, "not an MCAP recording"),
    (b"", "not an MCAP recording"),
    (None, "without a complete chunk"),               # cut just after its header
])
def test_what_cannot_be_reindexed_is_refused_in_one_line(tmp_path, content, says):
    bad = tmp_path / "bad.mcap"
    if content is None:
        whole = str(tmp_path / "whole.mcap")
        whole_file(whole, count=10)
        with open(whole, "rb") as f:
            header_end = make_reader(f).get_summary().chunk_indexes[0].chunk_start_offset
        cut_copy(whole, str(bad), header_end)
    else:
        bad.write_bytes(content)
    before = bad.read_bytes()
    refused = reindex(str(bad))
    assert refused.returncode == 2 and refused.stdout == "", refused
    assert refused.stderr.count("\n") == 1 and says in refused.stderr, refused.stderr
    assert "Traceback" not in refused.stderr and bad.read_bytes() == before
    assert not [p for p in os.listdir(tmp_path) if p.endswith(".reindexing")]


def test_a_new_recording_keeps_the_file_a_kill_cut_short_and_replaces_a_complete_one(tmp_path):
    path = str(tmp_path / "session.mcap")
    data = whole_file(path, count=500)
    cut_copy(path, path + ".cut", os.path.getsize(path) // 2)
    os.replace(path + ".cut", path)
    recording = Recording(path)                       # the next session, same file
    ((was, kept),) = recording.kept
    assert was == path and os.path.basename(kept).startswith("killed-")
    assert os.path.basename(kept).endswith("-session.mcap")
    write(recording, strings(3))
    recording.close()
    assert len(read_recording(path).messages) == 3
    done = reindex_file(kept)
    assert 0 < done.messages < 500 and opened_by_its_summary(kept)[1][0][3] == data[0]
    again = Recording(path)                           # a complete one is replaced, as before
    again.close()
    assert again.kept == [] and sorted(os.listdir(tmp_path)) == sorted(
        [os.path.basename(kept), "session.mcap"])
    cut_copy(kept, path, 1000)                        # killed again within the same second
    os.utime(path, ns=(os.stat(kept).st_mtime_ns,) * 2)
    third = Recording(path)
    third.close()
    ((_, kept_too),) = third.kept
    assert kept_too != kept and os.path.exists(kept) and os.path.exists(kept_too)
