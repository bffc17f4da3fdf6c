"""Writing a recording: MCAP files as rosbag2's MCAP storage writes them, one after another when
a size or duration limit splits the recording.

What rosbag2 (Jazzy) writes and this writes too: profile `ros2`; one schema per type, named
`pkg/msg/Name`, encoding `ros2msg`, the complete definition (`acti_record.definitions`); one
channel per topic, message encoding `cdr`, metadata `offered_qos_profiles` (the publishers' QoS,
YAML, metadata version 9) and `topic_type_hash` (RIHS01); log time = receive time, publish time
= the publisher's send time (ns since the epoch); a `rosbag2` metadata record holding the bag's
metadata YAML. Chunks are small and reach the disk as soon as they are full, and the recorder
flushes the one in progress every FLUSH_PERIOD_S: a process killed with -9 leaves a file whose
complete chunks can all be read (`acti_record.reading`) and written again whole
(`acti_record.reindexing`), which the next recording to the same name keeps (`keep_cut_file`)."""
from __future__ import annotations

import fcntl
import os
import time
from dataclasses import dataclass, field
from typing import Any

import yaml
from mcap.writer import CompressionType, Writer

from acti_record.reading import cut_short

PROFILE = "ros2"
SCHEMA_ENCODING = "ros2msg"
MESSAGE_ENCODING = "cdr"
LIBRARY = "acti_ros2 acti_record"
METADATA_VERSION = 9              # rosbag2 Jazzy's BagMetadata version
CHUNK_BYTES = 256 * 1024
FLUSH_PERIOD_S = 1.0
COMPRESSIONS = {"none": CompressionType.NONE, "zstd": CompressionType.ZSTD,
                "lz4": CompressionType.LZ4}


@dataclass(frozen=True)
class Topic:
    """A recorded topic: its name, type (`pkg/msg/Name`), complete definition (empty when no
    installed file defines it), publishers' QoS (rosbag2's keys, `qos_profile`) and type hash."""
    name: str
    type: str
    definition: str
    qos_profiles: tuple[dict, ...] = ()
    type_hash: str = ""


def qos_profile(history: str, depth: int, reliability: str, durability: str,
                deadline_ns: int, lifespan_ns: int, liveliness: str, lease_ns: int) -> dict:
    """One offered QoS profile as rosbag2 (metadata version 9) writes it: policies by name,
    durations as sec/nsec (infinite: 9223372036 s 854775807 ns)."""
    return {"history": history, "depth": depth, "reliability": reliability,
            "durability": durability, "deadline": _duration(deadline_ns),
            "lifespan": _duration(lifespan_ns), "liveliness": liveliness,
            "liveliness_lease_duration": _duration(lease_ns),
            "avoid_ros_namespace_conventions": False}


def _duration(ns: int) -> dict:
    return {"sec": ns // 1_000_000_000, "nsec": ns % 1_000_000_000}


def dump_yaml(value: Any) -> str:
    return yaml.safe_dump(value, sort_keys=False, default_flow_style=False)


class RecordedElsewhere(OSError):
    """The file is being written by another process (a recorder holds its lock)."""

    @classmethod
    def of(cls, path: str) -> RecordedElsewhere:
        return cls(f"{path} is being recorded (a recorder holds it): end the recorder first")


class _WriteThrough:
    """The file under the MCAP writer, unbuffered: a finished chunk is in the file at once. The
    file is locked (flock, exclusive) while it is written, so that no reindex rewrites it under
    a running recorder; a process killed with -9 leaves no lock behind."""

    def __init__(self, path: str) -> None:
        fd = os.open(path, os.O_WRONLY | os.O_CREAT, 0o666)
        try:                                  # locked before it is emptied
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(fd)
            raise RecordedElsewhere.of(path) from None
        os.ftruncate(fd, 0)
        self._file = open(fd, "wb", buffering=0)

    def write(self, data: bytes) -> int:
        view = memoryview(data)
        while view:
            view = view[self._file.write(view):]
        return len(data)

    def tell(self) -> int:
        return self._file.tell()

    def flush(self) -> None:
        pass

    def sync(self) -> None:
        os.fsync(self._file.fileno())

    def close(self) -> None:
        self._file.close()


def keep_cut_file(path: str) -> str:
    """A file at `path` that a kill cut short (MCAP without its summary or footer) renamed out
    of the way of a new recording to `killed-<its time>-<name>` beside it, so that starting
    again does not empty the recording of a crash; its new path, "" when there was none."""
    if not os.path.exists(path):
        return ""
    check_not_written(path)
    if not cut_short(path):
        return ""
    folder, name = os.path.split(path)
    stamp = time.strftime("%Y%m%d-%H%M%S", time.localtime(os.path.getmtime(path)))
    kept, n = os.path.join(folder, f"killed-{stamp}-{name}"), 1
    while os.path.exists(kept):           # two kills within a second
        n += 1
        kept = os.path.join(folder, f"killed-{stamp}-{n}-{name}")
    os.rename(path, kept)
    return kept


def check_not_written(path: str) -> None:
    """Raise RecordedElsewhere when a process is writing `path` (holds its lock)."""
    with open(path, "rb") as f:
        try:
            fcntl.flock(f, fcntl.LOCK_SH | fcntl.LOCK_NB)
        except BlockingIOError:
            raise RecordedElsewhere.of(path) from None


@dataclass
class _Counts:
    messages: int = 0
    first_ns: int = 0
    last_ns: int = 0
    per_topic: dict[str, int] = field(default_factory=dict)

    def add(self, topic: str, log_ns: int) -> None:
        if not self.messages:
            self.first_ns = log_ns
        self.messages += 1
        self.first_ns, self.last_ns = min(self.first_ns, log_ns), max(self.last_ns, log_ns)
        self.per_topic[topic] = self.per_topic.get(topic, 0) + 1


class McapFile:
    """One MCAP file of a recording. `name`: the file's name in its rosbag2 metadata (its own
    by default; a file written under a temporary name gives the name it will have)."""

    def __init__(self, path: str, compression: str = "none", chunk_bytes: int = CHUNK_BYTES,
                 name: str = "", library: str = LIBRARY) -> None:
        if compression not in COMPRESSIONS:
            raise ValueError(f"compression {compression!r}: use one of {', '.join(COMPRESSIONS)}")
        self.path, self.name = path, name or os.path.basename(path)
        self._stream = _WriteThrough(path)
        self._writer = Writer(self._stream, chunk_size=chunk_bytes,
                              compression=COMPRESSIONS[compression], enable_crcs=True)
        self._writer.start(profile=PROFILE, library=library)
        self._schemas: dict[tuple[str, str, str], int] = {}
        self._channels: dict[str, tuple[int, Topic]] = {}
        self.counts = _Counts()

    def channel(self, topic: Topic) -> int:
        """The channel id of `topic`, registered (with its schema) on first use, with rosbag2's
        channel metadata."""
        known = self._channels.get(topic.name)
        if known is not None:
            return known[0]
        return self.register(topic, SCHEMA_ENCODING if topic.definition else "",
                             MESSAGE_ENCODING,
                             {"offered_qos_profiles": dump_yaml(list(topic.qos_profiles)),
                              "topic_type_hash": topic.type_hash})

    def register(self, topic: Topic, schema_encoding: str, message_encoding: str,
                 metadata: dict[str, str]) -> int:
        """A new channel for `topic` with the encodings and metadata given (a reindexed file
        keeps its own), and its schema unless an equal one is registered; its id."""
        key = (topic.type, schema_encoding, topic.definition)
        schema = self._schemas.get(key)
        if schema is None:
            schema = self._schemas[key] = self._writer.register_schema(
                topic.type, schema_encoding, topic.definition.encode())
        channel = self._writer.register_channel(topic.name, message_encoding, schema, metadata)
        self._channels[topic.name] = (channel, topic)
        return channel

    def write(self, topic: Topic, data: bytes, log_ns: int, publish_ns: int) -> None:
        self.write_to(self.channel(topic), topic.name, data, log_ns, publish_ns)

    def write_to(self, channel: int, topic: str, data: bytes, log_ns: int, publish_ns: int,
                 sequence: int = 0) -> None:
        """A message on a registered channel."""
        self._writer.add_message(channel, log_ns, data, publish_ns, sequence)
        self.counts.add(topic, log_ns)

    def add_metadata(self, name: str, data: dict[str, str]) -> None:
        """A metadata record other than rosbag2's (which `close` writes)."""
        self._writer.add_metadata(name, data)

    def add_attachment(self, create_ns: int, log_ns: int, name: str, media_type: str,
                       data: bytes) -> None:
        self._writer.add_attachment(create_ns, log_ns, name, media_type, data)

    def flush(self) -> None:
        """Write the chunk in progress to the file (the recorder does every FLUSH_PERIOD_S)."""
        self._writer.flush()

    @property
    def size(self) -> int:
        return self._stream.tell()

    def close(self, sync: bool = False) -> None:
        """The rosbag2 metadata record, then MCAP's summary and footer; with `sync`, on the
        disk before this returns."""
        self._writer.add_metadata("rosbag2", {"serialized_metadata": dump_yaml(self._metadata())})
        self._writer.finish()
        if sync:
            self._stream.sync()
        self._stream.close()

    def _metadata(self) -> dict:
        """rosbag2's BagMetadata of this file alone."""
        c, name = self.counts, self.name
        start, duration = {"nanoseconds_since_epoch": c.first_ns}, {"nanoseconds": c.last_ns - c.first_ns}
        return {
            "version": METADATA_VERSION, "storage_identifier": "mcap",
            "duration": duration, "starting_time": start, "message_count": c.messages,
            "topics_with_message_count": [
                {"topic_metadata": {"name": t.name, "type": t.type,
                                    "serialization_format": MESSAGE_ENCODING,
                                    "offered_qos_profiles": list(t.qos_profiles),
                                    "type_description_hash": t.type_hash},
                 "message_count": c.per_topic.get(t.name, 0)}
                for _, t in self._channels.values()],
            "compression_format": "", "compression_mode": "",
            "relative_file_paths": [name],
            "files": [{"path": name, "starting_time": start, "duration": duration,
                       "message_count": c.messages}],
            "custom_data": {}, "ros_distro": "jazzy",
        }


class Recording:
    """The files of one recording. Without limits one file, `path`; with a size (bytes) or
    duration (s) limit, `stem_0.mcap`, `stem_1.mcap` … as rosbag2 names its split files, the
    next one started when the current one reaches a limit."""

    def __init__(self, path: str, max_bytes: int = 0, max_duration_s: float = 0.0,
                 compression: str = "none") -> None:
        if max_bytes < 0 or max_duration_s < 0:
            raise ValueError("the size and duration limits must be 0 (none) or positive")
        self.path, self.max_bytes, self.max_duration_ns = path, max_bytes, int(max_duration_s * 1e9)
        self.compression = compression
        self.paths: list[str] = []
        self.kept: list[tuple[str, str]] = []      # files a kill cut short: (path, renamed to)
        self.messages = 0
        self._file = self._open()

    def _open(self) -> McapFile:
        split = self.max_bytes or self.max_duration_ns
        stem = self.path.removesuffix(".mcap")
        path = f"{stem}_{len(self.paths)}.mcap" if split else self.path
        kept = keep_cut_file(path)
        if kept:
            self.kept.append((path, kept))
        self.paths.append(path)
        return McapFile(path, self.compression)

    def write(self, topic: Topic, data: bytes, log_ns: int, publish_ns: int) -> None:
        if self._full(log_ns):
            self._file.close()
            self._file = self._open()
        self._file.write(topic, data, log_ns, publish_ns)
        self.messages += 1

    def _full(self, log_ns: int) -> bool:
        counts = self._file.counts
        if not counts.messages:
            return False
        return bool(self.max_bytes and self._file.size >= self.max_bytes
                    or self.max_duration_ns and log_ns - counts.first_ns >= self.max_duration_ns)

    def flush(self) -> None:
        self._file.flush()

    def close(self) -> None:
        self._file.close()
