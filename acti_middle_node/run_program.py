"""Run a STROLIC or RoboLine program file on the running arm node and show its progress:

    python -m acti_middle_node.run_program FILE [--node /acti_middle_node] [--budget N] [--quiet]
        [--data POINTS] [--break LINE ...] [--step] [--check]

FILE is the text form (.sasm, .txt, .strolic) or raw code (anything else); it is assembled here
and sent as code to ~/run_program. A RoboLine program (.rbl) is compiled here (errors are shown
as file:line:column) and sent as source with its taught data (--data, default FILE.pts), with
its breakpoints (--break) or stopped at its first line (--step; ~/program_debug goes on); with
--check it is not run but checked (~/check_program: every move line, reachable or not, and the
program's time) and the exit status is 0 when every move is reachable. Progress lines show the program counter (byte offset, as
`python -m strolic dis --offsets` numbers the codes), the state and the arm's motion; at the end
the console lines, what the program sent, the final stack and the exception report if any.
Ctrl-C cancels the run (the program and the arm stop); Ctrl-C before the program was sent, or
again while the cancel is under way, ends this command at once (the node still cancels). Exit
status: 0 the program finished, 1 an exception stopped it, 2 it was canceled, interrupted or did
not load, 3 no node answered (or it went away).
"""
from __future__ import annotations

import argparse
import contextlib
import signal
import sys
import time
from pathlib import Path
from typing import Iterator

import rclpy
from acti_msgs.action import RunProgram
from rclpy.action import ActionClient
from rclpy.signals import SignalHandlerOptions

from acti_msgs.srv import CheckProgram
from roboline import SourceError
from roboline.__main__ import POINTS_SUFFIX, compile_file
from strolic.__main__ import load_program
from strolic.errors import StrolicError

ROBOLINE_SUFFIX = ".rbl"

SERVER_TIMEOUT = 30.0
SERVER_LOST = 5.0        # s without the action server: the node has gone


def describe(feedback: RunProgram.Feedback) -> str:
    motion = (f"motion {feedback.motion_id} {feedback.motion_label} "
              f"{100 * feedback.progress:.0f} % (+{feedback.queue_length} queued)"
              if feedback.motion_id else "arm at rest")
    state = f"{feedback.state}: {feedback.message}" if feedback.message else feedback.state
    where = f"line {feedback.line:<4}" if feedback.line else f"@{feedback.program_counter:<6}"
    return (f"{where} {feedback.instructions:>8} instructions  "
            f"{state:<18} {motion}")


def report(result: RunProgram.Result, out=sys.stdout) -> None:
    for line in result.console:
        print(f"console: {line}", file=out)
    for line in result.output:
        print(f"output: {line}", file=out)
    print(f"stack: {' '.join(result.stack) if result.stack else '(empty)'}", file=out)
    status = {RunProgram.Result.FINISHED: "finished", RunProgram.Result.EXCEPTION: "exception",
              RunProgram.Result.CANCELED: "canceled", RunProgram.Result.INVALID: "invalid"}
    print(f"{status.get(result.status, result.status)} after {result.instructions} "
          f"instructions, {result.duration:.2f} s (simulated)", file=out)
    if result.exception:
        print(result.exception, file=out)


def wait_for(node, client: ActionClient, future) -> bool:
    """Spin until `future` is done; False (and a message) when the node goes away meanwhile."""
    gone_since = None
    while not future.done():
        rclpy.spin_until_future_complete(node, future, timeout_sec=1.0)
        if client.server_is_ready():
            gone_since = None
        elif gone_since is None:
            gone_since = time.monotonic()
        elif time.monotonic() - gone_since > SERVER_LOST:
            print("the node went away before the program ended", file=sys.stderr)
            return False
    return True


def goal_fields(args: argparse.Namespace) -> dict:
    """The goal's program fields: code, or a RoboLine source (compiled here first: its errors
    are shown before anything is sent) with its taught data."""
    path = Path(args.program)
    if path.suffix != ROBOLINE_SUFFIX:
        return {"code": list(load_program(path))}
    compile_file(path, args.data)
    data = args.data or path.with_suffix(POINTS_SUFFIX)
    return {"source": path.read_text(), "source_name": str(path),
            "points": data.read_text() if data.exists() else "",
            "breakpoints": args.breaks, "step": args.step}


def run(args: argparse.Namespace) -> int:
    try:
        fields = goal_fields(args)
    except StrolicError as error:
        print(f"{args.program}: {error.report()}", file=sys.stderr)
        return 2
    except SourceError as error:
        print(error.report(), file=sys.stderr)
        return 2
    except (OSError, UnicodeDecodeError) as error:     # no such file; a text form not in UTF-8
        print(f"{args.program}: {error}", file=sys.stderr)
        return 2
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)   # Ctrl-C: cancel, then report
    node = client = None
    try:        # a Ctrl-C from here on is one line: also while the client is being made (its
        # node is in the graph before then: a traceback came out of the type support's import)
        node = rclpy.create_node("run_program")
        if args.check:
            return check(args, fields, node)
        client = ActionClient(node, RunProgram, f"{args.node.rstrip('/')}/run_program")
        return _send_and_follow(args, fields, node, client)
    except KeyboardInterrupt:       # before the program was sent, or again while canceling
        print("interrupted", file=sys.stderr)
        return 2
    finally:
        if client is not None:
            client.destroy()
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()


def check(args: argparse.Namespace, fields: dict, node) -> int:
    """~/check_program: a line a move, then the total; 0 when every move is reachable."""
    if "source" not in fields:
        print("--check takes a RoboLine program (.rbl)", file=sys.stderr)
        return 2
    client = node.create_client(CheckProgram, f"{args.node.rstrip('/')}/check_program")
    if not client.wait_for_service(timeout_sec=SERVER_TIMEOUT):
        print(f"no {args.node}/check_program answered in {SERVER_TIMEOUT:g} s", file=sys.stderr)
        return 3
    future = client.call_async(CheckProgram.Request(
        source=fields["source"], source_name=fields["source_name"], points=fields["points"]))
    rclpy.spin_until_future_complete(node, future)
    answer = future.result()
    lines = fields["source"].splitlines()
    for m in answer.moves:
        text = lines[m.line - 1].strip() if 0 < m.line <= len(lines) else ""
        print(f"{fields['source_name']}:{m.line}: {m.command:<6} {m.verdict:<18} "
              f"{m.duration:7.2f} s  {text}" + (f"  ({m.reason})" if m.reason else ""))
    print(f"total {answer.total_time:.2f} s (simulated)"
          + (f"; {answer.message}" if answer.message else ""))
    return 0 if answer.success else 1


def _send_and_follow(args: argparse.Namespace, fields: dict, node, client: ActionClient) -> int:
    """Send the program, show its progress, cancel it on Ctrl-C; the exit status."""
    if not client.wait_for_server(timeout_sec=SERVER_TIMEOUT):
        print(f"no {args.node}/run_program answered in {SERVER_TIMEOUT:g} s", file=sys.stderr)
        return 3
    last = [None]

    def show(message) -> None:
        """A line when the state or the motion changes (every message with --verbose)."""
        f = message.feedback
        key = (f.state, f.message, f.motion_id, int(4 * f.progress))
        if args.verbose or not args.quiet and key != last[0]:
            print(describe(f), flush=True)
        last[0] = key
    goal = RunProgram.Goal(budget=args.budget, **fields)
    with _sigint_ignored():     # until accepted: a Ctrl-C then would leave the run uncanceled
        sent = client.send_goal_async(goal, feedback_callback=show)
        rclpy.spin_until_future_complete(node, sent)
    handle = sent.result()
    if not handle.accepted:
        print("the node refused the program (another one is running?)", file=sys.stderr)
        return 2
    done = handle.get_result_async()
    try:
        if not wait_for(node, client, done):
            return 3
    except KeyboardInterrupt:
        print("canceling ...", file=sys.stderr)
        rclpy.spin_until_future_complete(node, handle.cancel_goal_async(), timeout_sec=10.0)
        if not wait_for(node, client, done):
            return 3
    result = done.result().result
    report(result)
    return {RunProgram.Result.FINISHED: 0, RunProgram.Result.EXCEPTION: 1}.get(result.status, 2)


@contextlib.contextmanager
def _sigint_ignored() -> Iterator[None]:
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m acti_middle_node.run_program",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("program", help="the program: text form (.sasm) or raw code")
    parser.add_argument("--node", default="/acti_middle_node", help="the arm node's name")
    parser.add_argument("--budget", type=int, default=0, help="instruction limit (0: none)")
    parser.add_argument("--quiet", action="store_true", help="no progress lines")
    parser.add_argument("--verbose", action="store_true", help="every feedback message")
    parser.add_argument("--data", type=Path, help="RoboLine: the taught data (default FILE.pts)")
    parser.add_argument("--break", dest="breaks", type=int, action="append", default=[],
                        metavar="LINE", help="RoboLine: stop at this line (repeatable)")
    parser.add_argument("--step", action="store_true", help="RoboLine: stop at the first line")
    parser.add_argument("--check", action="store_true",
                        help="RoboLine: check the program on a fresh arm instead of running it")
    return run(parser.parse_args(argv))


if __name__ == "__main__":
    sys.exit(main())
