"""Reindexing a recording cut short: what `ros2 bag reindex` is to rosbag2.

A recorder killed with -9 (or a power cut) leaves a file without its summary, indexes and
footer, and without the rosbag2 metadata record; readers that open a file by its summary
(rosbags, `ros2 bag`, the mcap library's indexed reader) refuse it. Reindexing reads every
record before the cut (`reading.FileRecords`) and writes the file again whole with the mcap
library's writer (`writing.McapFile`): the header's library, the schemas, the channels with
their own metadata (`offered_qos_profiles`, `topic_type_hash`), every message with its bytes,
times and sequence, in their order, the other metadata records and attachments, the rosbag2
metadata record with the messages counted again, then summary, indexes and footer, and its
chunks compressed as they were. It is written beside the file under a temporary name and
renamed over it, so that an interrupted reindex leaves the file as it was."""
from __future__ import annotations

import os
import shutil
import tempfile
from dataclasses import dataclass

from mcap.records import (Attachment, Channel as McapChannel, Header, Message as McapMessage,
                          Metadata, Schema)

from acti_record.reading import FileRecords, channel_of, summary_messages
from acti_record.writing import LIBRARY, McapFile, Topic, check_not_written

BAG_METADATA = "rosbag2"      # the metadata record rosbag2 reads, written again with new counts
COMPRESSION_NAMES = {"": "none", "zstd": "zstd", "lz4": "lz4"}


@dataclass(frozen=True)
class Reindexed:
    path: str
    messages: int
    lost: str = ""            # where it was cut and what was read ("" for a complete file)

    @property
    def text(self) -> str:
        if not self.lost:
            return f"{self.path}: already complete ({self.messages} messages), left alone"
        return f"reindexed {self.path} ({self.messages} messages): it {self.lost}"


def reindex_file(path: str) -> Reindexed:
    """The file `path` rewritten whole when it is cut short, left alone when it is complete.
    Raises `reading.BadRecording` for what cannot be reindexed (not MCAP, no complete chunk),
    `writing.RecordedElsewhere` for a file that a recorder is still writing."""
    check_not_written(path)
    complete = summary_messages(path)
    if complete is not None:
        return Reindexed(path, complete)
    folder, name = os.path.split(os.path.abspath(path))
    fd, temporary = tempfile.mkstemp(prefix=f".{name}.", suffix=".reindexing", dir=folder)
    os.close(fd)
    try:
        records = _rewrite(path, temporary, name)
        shutil.copymode(path, temporary)
        os.replace(temporary, path)
    except BaseException:
        os.unlink(temporary)
        raise
    _sync_folder(folder)
    return Reindexed(path, records.messages, records.problem)


def _rewrite(path: str, into: str, name: str) -> FileRecords:
    """Every record of `path` before its cut, written to `into` as a complete file named
    `name`; what was read (its messages, what was lost)."""
    records = FileRecords(path)
    library = LIBRARY
    out: McapFile | None = None
    schemas: dict[int, Schema] = {}
    channels: dict[int, tuple[int, str]] = {}          # old id: new id, topic
    for record in records:
        if isinstance(record, Header):
            library = record.library or LIBRARY
            continue
        if out is None:                  # after the first chunk's start: its compression known
            out = McapFile(into, COMPRESSION_NAMES.get(records.compression, "none"),
                           name=name, library=library)
        if isinstance(record, Schema):
            schemas[record.id] = record
        elif isinstance(record, McapChannel) and record.id not in channels:
            schema = schemas.get(record.schema_id)
            c = channel_of(record, schema)
            topic = Topic(c.topic, c.type, c.definition, c.qos_profiles, c.type_hash)
            channels[record.id] = (out.register(topic, schema.encoding if schema else "",
                                                record.message_encoding, dict(record.metadata)),
                                   record.topic)
        elif isinstance(record, McapMessage) and record.channel_id in channels:
            channel, topic = channels[record.channel_id]
            out.write_to(channel, topic, bytes(record.data), record.log_time,
                         record.publish_time, record.sequence)
        elif isinstance(record, Metadata) and record.name != BAG_METADATA:
            out.add_metadata(record.name, dict(record.metadata))
        elif isinstance(record, Attachment):
            out.add_attachment(record.create_time, record.log_time, record.name,
                               record.media_type, bytes(record.data))
    assert out is not None               # FileRecords refuses a file without a record
    out.close(sync=True)
    return records


def _sync_folder(folder: str) -> None:
    """The rename on the disk too."""
    fd = os.open(folder, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)
