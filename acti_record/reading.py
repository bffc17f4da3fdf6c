"""Reading a recording back: every complete message of one or more MCAP files, in log-time order.

Files are read record by record, without the summary at their end, so that a file whose
recorder was killed (no summary, a chunk cut short) gives every message of its complete chunks:
what is missing is said (`Contents.problem`), not raised. What is not a recording at all (no
MCAP magic, a file that is not there, nothing readable) raises `BadRecording` with one line that
says what was wrong."""
from __future__ import annotations

import glob
import os
import shlex
import struct
from dataclasses import dataclass, field
from typing import Iterator

import yaml
from mcap.exceptions import EndOfFile, McapError
from mcap.reader import make_reader
from mcap.records import (Channel as McapChannel, Chunk, DataEnd, McapRecord,
                          Message as McapMessage, Schema)
from mcap.stream_reader import StreamReader, breakup_chunk


MAGIC = b"\x89MCAP0\r\n"
REINDEX_COMMAND = "python -m acti_bringup.reindex"   # rewrites a file cut short whole
# what a damaged file raises from inside the mcap reader
READ_ERRORS = (McapError, struct.error, ValueError, UnicodeDecodeError, EOFError, MemoryError)
RECORD_LIMIT = 1 << 30        # a longer record is damage, not a record


class BadRecording(Exception):
    """The file cannot be read as a recording; the text says why."""


@dataclass(frozen=True)
class Channel:
    topic: str
    type: str                 # pkg/msg/Name, the schema's name
    definition: str           # the schema's text
    encoding: str             # the messages' (cdr)
    qos_profiles: tuple = ()  # rosbag2's offered_qos_profiles, parsed
    type_hash: str = ""


@dataclass(frozen=True)
class Message:
    channel: Channel
    log_ns: int
    publish_ns: int
    data: bytes


@dataclass
class Contents:
    files: list[str]
    messages: list[Message] = field(default_factory=list)
    problem: str = ""         # what could not be read (a file cut short), "" when all was

    @property
    def channels(self) -> list[Channel]:
        seen: dict[str, Channel] = {}
        for m in self.messages:
            seen.setdefault(m.channel.topic, m.channel)
        return list(seen.values())


def recording_files(path: str) -> list[str]:
    """The files of the recording `path`: the file itself, a folder's .mcap files, or the
    split files `stem_0.mcap`, `stem_1.mcap` … of a recording started as `stem.mcap`."""
    if os.path.isdir(path):
        found = sorted(glob.glob(os.path.join(path, "*.mcap")), key=_split_index)
    elif os.path.exists(path):
        found = [path]
    else:
        found = sorted(glob.glob(glob.escape(path.removesuffix(".mcap")) + "_[0-9]*.mcap"),
                       key=_split_index)
    if not found:
        raise BadRecording(f"{path}: no such recording (no file, folder or split files "
                           f"{path.removesuffix('.mcap')}_0.mcap …)")
    return found


def _split_index(path: str) -> tuple[int, str]:
    tail = path.removesuffix(".mcap").rsplit("_", 1)[-1]
    return (int(tail) if tail.isdigit() else -1, path)


def summary_messages(path: str) -> int | None:
    """The message count of a complete file (its footer and summary readable), else None."""
    try:
        with open(path, "rb") as f:
            summary = make_reader(f).get_summary()
    except (OSError, *READ_ERRORS):
        return None
    if summary is None:
        return None
    return summary.statistics.message_count if summary.statistics else 0


def cut_short(path: str) -> bool:
    """The file is an MCAP file without its summary or footer: a recorder killed."""
    try:
        with open(path, "rb") as f:
            if f.read(len(MAGIC)) != MAGIC:
                return False
    except OSError:
        return False
    return summary_messages(path) is None


def read_recording(path: str) -> Contents:
    """Every readable message of the recording `path` (`recording_files`), by log time. A file
    of several that cannot be read is a problem of the recording (a recorder killed as it
    started its next split file leaves one without a chunk); when none can, it is refused."""
    contents = Contents(recording_files(path))
    problems, refused = [], []
    for file in contents.files:
        try:
            problem = _read_file(file, contents.messages)
        except BadRecording as e:        # one of split files (the last one, just started)
            refused.append(e)
            problem = str(e)
        if problem:
            problems.append(problem)
    if len(refused) == len(contents.files):
        raise refused[0]
    contents.messages.sort(key=lambda m: m.log_ns)
    contents.problem = "; ".join(problems)
    return contents


class FileRecords:
    """The records of one MCAP file in file order, the chunks' records in place of each chunk,
    read one after another without the summary, so that a file cut short gives every record
    before the cut. Once iterated: `complete` (its footer was read), else `problem` says where
    it was cut and what was read ("ends early …"); `compression`: its chunks' ("" none)."""

    def __init__(self, path: str) -> None:
        self.path = path
        self.compression = ""
        self.messages = 0
        self.complete = False
        self.problem = ""

    def __iter__(self) -> Iterator[McapRecord]:
        content, data_ended = False, False
        try:
            with open(self.path, "rb") as f:
                if f.read(len(MAGIC)) != MAGIC:
                    raise BadRecording(f"{self.path}: not an MCAP recording (it does not start "
                                       "as one)")
                f.seek(0)
                for record in StreamReader(f, emit_chunks=True,
                                           record_size_limit=RECORD_LIMIT).records:
                    if isinstance(record, Chunk):
                        self.compression = self.compression or record.compression
                    for inner in breakup_chunk(record) if isinstance(record, Chunk) else (record,):
                        content |= isinstance(inner, (Schema, McapChannel, McapMessage))
                        self.messages += isinstance(inner, McapMessage)
                        yield inner
                    data_ended |= isinstance(record, DataEnd)
            self.complete = True
        except OSError as e:
            raise BadRecording(f"{self.path}: cannot be read: {e.strerror or e}") from None
        except READ_ERRORS as e:
            if not content:
                raise BadRecording(f"{self.path}: an MCAP file without a complete chunk "
                                   f"({_what(e)}: was its recorder killed as it started?)") from None
            self.problem = (
                f"has its summary cut short: all {self.messages} messages were read "
                "(was the recorder killed as it closed the file?)" if data_ended else
                f"ends early ({_what(e)}): its last chunk is lost, {self.messages} messages "
                "before it were read (was the recorder killed?)")


def _read_file(path: str, into: list[Message]) -> str:
    """Append the file's messages to `into`; what was lost, if anything ("" when nothing),
    with the command that makes the file whole for readers that need its summary."""
    schemas: dict[int, Schema] = {}
    channels: dict[int, Channel] = {}
    records = FileRecords(path)
    for record in records:
        if isinstance(record, Schema):
            schemas[record.id] = record
        elif isinstance(record, McapChannel):
            channels[record.id] = channel_of(record, schemas.get(record.schema_id))
        elif isinstance(record, McapMessage):
            channel = channels.get(record.channel_id)
            if channel is not None:
                into.append(Message(channel, record.log_time, record.publish_time,
                                    bytes(record.data)))
    if not records.problem:
        return ""
    return (f"{path} {records.problem}; `{REINDEX_COMMAND} {shlex.quote(path)}` rewrites it whole "
            "(summary, indexes, footer) for readers that need them (rosbags, ros2 bag)")


def _what(error: Exception) -> str:
    if isinstance(error, (EndOfFile, struct.error)):     # a record or a field ends too soon
        return "the file is cut short"
    return str(error) or type(error).__name__


def channel_of(record: McapChannel, schema: Schema | None) -> Channel:
    try:
        qos = tuple(yaml.safe_load(record.metadata.get("offered_qos_profiles", "")) or ())
    except yaml.YAMLError:
        qos = ()
    return Channel(topic=record.topic, type=schema.name if schema else "",
                   definition=bytes(schema.data).decode(errors="replace") if schema else "",
                   encoding=record.message_encoding, qos_profiles=qos,
                   type_hash=record.metadata.get("topic_type_hash", ""))
