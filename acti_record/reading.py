"""Reading a recording back: every complete message of one or more MCAP files, in log-time order.

Files are read record by record, without the summary at their end, so that a file whose
recorder was killed (no summary, a chunk cut short) gives every message of its complete chunks:
what is missing is said (`Contents.problem`), not raised. What is not a recording at all (no
MCAP magic, a file that is not there, nothing readable) raises `BadRecording` with one line that
says what was wrong."""
from __future__ import annotations

import glob
import os
import struct
from dataclasses import dataclass, field

import yaml
from mcap.exceptions import McapError
from mcap.records import Channel as McapChannel, Message as McapMessage, Schema
from mcap.stream_reader import StreamReader


MAGIC = b"\x89MCAP0\r\n"


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


def read_recording(path: str) -> Contents:
    """Every readable message of the recording `path` (`recording_files`), by log time."""
    contents = Contents(recording_files(path))
    problems = []
    for file in contents.files:
        problem = _read_file(file, contents.messages)
        if problem:
            problems.append(problem)
    contents.messages.sort(key=lambda m: m.log_ns)
    contents.problem = "; ".join(problems)
    return contents


# what a damaged file raises from inside the mcap reader
_DAMAGE = (McapError, struct.error, ValueError, UnicodeDecodeError, EOFError, MemoryError)


def _read_file(path: str, into: list[Message]) -> str:
    """Append the file's messages to `into`; the problem met, if any ("" when none)."""
    schemas: dict[int, Schema] = {}
    channels: dict[int, Channel] = {}
    count = 0
    try:
        with open(path, "rb") as f:
            if f.read(len(MAGIC)) != MAGIC:
                raise BadRecording(f"{path}: not an MCAP recording (it does not start as one)")
            f.seek(0)
            records = StreamReader(f, record_size_limit=1 << 30).records
            for record in records:
                if isinstance(record, Schema):
                    schemas[record.id] = record
                elif isinstance(record, McapChannel):
                    channels[record.id] = _channel(record, schemas.get(record.schema_id))
                elif isinstance(record, McapMessage):
                    channel = channels.get(record.channel_id)
                    if channel is not None:
                        into.append(Message(channel, record.log_time, record.publish_time,
                                            bytes(record.data)))
                        count += 1
    except OSError as e:
        raise BadRecording(f"{path}: cannot be read: {e.strerror or e}") from None
    except _DAMAGE as e:
        if not schemas and not channels and not count:
            raise BadRecording(f"{path}: an MCAP file without a complete chunk ({_what(e)}: "
                               "was its recorder killed as it started?)") from None
        return (f"{path} ends early ({_what(e)}): its last chunk is lost, {count} messages "
                "before it were read (was the recorder killed?)")
    return ""


def _what(error: Exception) -> str:
    text = str(error) or type(error).__name__
    return {"EndOfFile": "the file is cut short"}.get(type(error).__name__, text)


def _channel(record: McapChannel, schema: Schema | None) -> Channel:
    try:
        qos = tuple(yaml.safe_load(record.metadata.get("offered_qos_profiles", "")) or ())
    except yaml.YAMLError:
        qos = ()
    return Channel(topic=record.topic, type=schema.name if schema else "",
                   definition=bytes(schema.data).decode(errors="replace") if schema else "",
                   encoding=record.message_encoding, qos_profiles=qos,
                   type_hash=record.metadata.get("topic_type_hash", ""))
