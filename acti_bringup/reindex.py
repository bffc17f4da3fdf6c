"""Reindex recordings cut short, as `ros2 bag reindex` does for rosbag2: a recorder killed with
-9 (or a power cut) leaves a file whose summary, indexes and footer are missing, which rosbags,
`ros2 bag` and the mcap library's indexed reader refuse. Each file is written again whole from
what it holds before the cut (at most its last chunk, the last second, is lost), in place; a
complete file is left alone (docs/recording.md).

    python -m acti_bringup.reindex FILE.mcap [FILE.mcap ...]
        a file, a folder of them, or the stem of split files (STEM.mcap: STEM_0.mcap …)

A file that is not MCAP, holds no complete chunk or is still being recorded: one line saying
why, exit status 2.
"""
from __future__ import annotations

import argparse
import sys

from acti_record.reading import BadRecording, recording_files
from acti_record.reindexing import reindex_file


def parse(args: list[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="python -m acti_bringup.reindex",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("paths", metavar="FILE.mcap", nargs="+",
                        help="a recording (a file, a folder, or the stem of split files)")
    return parser.parse_args(args)


def main(args: list[str] | None = None) -> None:
    options = parse(sys.argv[1:] if args is None else args)
    status = 0
    for path in options.paths:
        try:
            files = recording_files(path)
        except BadRecording as e:
            files = []
            print(f"reindex: {e}", file=sys.stderr)
            status = 2
        for file in files:               # one file refused, the others still reindexed
            try:
                print(reindex_file(file).text)
            except (BadRecording, OSError) as e:
                print(f"reindex: {e}", file=sys.stderr)
                status = 2
    raise SystemExit(status)


if __name__ == "__main__":
    main()
