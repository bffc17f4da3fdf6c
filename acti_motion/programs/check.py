"""Check before motion: a RoboLine program run against a fresh arm (a world of its own, the live
arm's settings and pose) in simulated time, as fast as it computes, without moving the live
arm. Every move command reports reachable, unreachable or outside a soft limit, with the time
its motions took; the program's total time; an endless program is cut at a budget."""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

from acti_motion.arm.core import ArmCore
from acti_motion.executor import MotionExecutor
from acti_motion.programs.robot import FLAG_RANGE, Flag, ProgramDefaults, RobotHost
from acti_motion.programs.run import ProgramRun, Status
from acti_sim.world import World
from roboline import Program
from strolic.errors import ExceptionKind as K

REACHABLE, UNREACHABLE = "reachable", "unreachable"
OUTSIDE_SOFT_LIMIT, REFUSED = "outside soft limit", "refused"
MOVES = {"AJMOVE", "IJMOVE", "ALMOVE", "ILMOVE", "HMOVE", "CMOVE1", "CMOVE3", "ADRIVE", "IDRIVE",
         "GRASP"}
BUDGET_S = 600.0                # simulated seconds a check may take
INSTRUCTIONS = 20_000_000       # instructions a check may execute (a loop without motions)


@dataclass
class CheckedMove:
    line: int
    command: str
    verdict: str = REACHABLE
    duration: float = 0.0
    reason: str = ""
    runs: int = 1                       # how often the line ran (a loop): the longest shown
    motions: list[int] = field(default_factory=list)


@dataclass
class CheckResult:
    success: bool
    message: str
    moves: list[CheckedMove]
    total_time: float
    cut: bool


def verdict_of(flag: Flag) -> str:
    if flag.code == FLAG_RANGE and "soft limit" in flag.reason:
        return OUTSIDE_SOFT_LIMIT
    return UNREACHABLE if flag.code in (FLAG_RANGE, 3) else REFUSED


class CheckHost(RobotHost):
    """A RobotHost that notes, for every move command, its source line, its verdict and the
    motions it queued."""

    def __init__(self, arm: ArmCore, program: Program, **options) -> None:
        super().__init__(arm, **options)
        self.program = program
        self.vm = None
        self.moves: list[CheckedMove] = []
        self._queued: list[int] = []

    def _issued(self, motion_id: int) -> None:
        super()._issued(motion_id)
        self._queued.append(motion_id)

    def _flag(self, proc, name: str, error: Flag | None) -> None:
        if name in MOVES:
            frame = self.vm.main.frame
            offset = self.vm.program_offset(self.vm.main, frame, frame.codes[frame.pc - 1][2])
            move = CheckedMove(self.program.line_at(offset), name, motions=self._queued)
            if error is not None:
                move.verdict, move.reason = verdict_of(error), error.reason
            self.moves.append(move)
        self._queued = []
        super()._flag(proc, name, error)


def fresh_arm(live: ArmCore, executor: MotionExecutor) -> ArmCore:
    """An arm like `live`: its settings in force, where it stands, servo as it is."""
    joints = tuple(float(x) for x in live.get_feedback_pos_joint().values["pos"][:live.axis_count])
    config = replace(live.config, initial_joints_deg=joints,
                     home_joints_deg=tuple(float(x) for x in live.home),
                     accel_time_joint=live.accel_time_joint,
                     min_accel_time_joint=live.min_accel_time_joint,
                     accel_time_cartesian=live.accel_time_cartesian,
                     min_accel_time_cartesian=live.min_accel_time_cartesian,
                     max_speed_translation=live.max_speed_cartesian[0],
                     max_speed_rotation=live.max_speed_cartesian[1],
                     soft_limit_cartesian=live.soft_limit_box())
    arm = ArmCore(executor, config)
    arm.soft_limit_joint = live.soft_limit_joint.copy()
    arm.max_speed_joint = live.max_speed_joint.copy()
    arm.frames = live.frames
    if live.servo:
        arm.servo_on()
    return arm


def check_program(program: Program, live: ArmCore, defaults: ProgramDefaults | None = None,
                  budget_s: float = BUDGET_S, instructions: int = INSTRUCTIONS) -> CheckResult:
    """Run `program` on a fresh arm like `live` (which does not move) in simulated time."""
    world = World()
    try:
        executor = MotionExecutor(world, real_time_factor=0.0)
        arm = fresh_arm(live, executor)
        starts: dict[int, float] = {}
        ends: dict[int, float] = {}
        host: CheckHost

        def step() -> None:
            executor.step()
            current = arm.device.current
            if current is not None:
                starts.setdefault(current.id, world.time)
            for move in host.moves:
                for motion in move.motions:
                    if motion not in ends and arm.device.is_over(motion):
                        ends[motion] = world.time
            if world.time > budget_s:
                host.cancel_event.set()
        host = CheckHost(arm, program, step=step, defaults=defaults)
        run = ProgramRun(arm, program, host=host, budget=instructions)
        host.vm = run.vm
        result = run.run()
        cut = result.status is Status.CANCELED or (
            result.error is not None and result.error.kind is K.INSTRUCTION_BUDGET)
        for move in host.moves:
            times = [(starts[m], ends.get(m, world.time)) for m in move.motions if m in starts]
            if times:
                move.duration = max(e for _, e in times) - min(s for s, _ in times)
        if result.error is not None and result.error.kind is K.OUT_OF_OPERATING_REGION:
            running = [m for m in host.moves if any(i in starts and i not in ends
                                                    for i in m.motions)]
            for move in running[:1]:
                move.verdict, move.reason = OUTSIDE_SOFT_LIMIT, result.error.detail
        if cut:
            message = (f"cut after {budget_s:g} s of simulated time" if result.status is
                       Status.CANCELED else f"cut after {instructions} instructions")
        else:
            message = result.report
        moves = by_line(host.moves)
        ok = result.status is Status.FINISHED and all(m.verdict == REACHABLE for m in moves)
        total = min(result.duration, budget_s) if math.isfinite(result.duration) else budget_s
        return CheckResult(ok, message, moves, total, cut)
    finally:
        world.close()


def by_line(moves: list[CheckedMove]) -> list[CheckedMove]:
    """One entry a source line and command, in the order first run: its worst verdict (the
    first that was not reachable) and its longest duration."""
    lines: dict[tuple[int, str], CheckedMove] = {}
    for move in moves:
        seen = lines.get((move.line, move.command))
        if seen is None:
            lines[(move.line, move.command)] = replace(move, motions=[])
            continue
        seen.runs += 1
        seen.duration = max(seen.duration, move.duration)
        if seen.verdict == REACHABLE and move.verdict != REACHABLE:
            seen.verdict, seen.reason = move.verdict, move.reason
    return list(lines.values())


def summary(result: CheckResult, program: Program) -> list[str]:
    """The check as lines of text: one a move, then the total."""
    lines = [f"{program.source.name}:{m.line}: {m.command:<6} {m.verdict:<18} "
             f"{m.duration:7.2f} s{f' ({m.runs} runs)' if m.runs > 1 else ''}  "
             f"{program.source.line(m.line).strip()}"
             + (f"  ({m.reason})" if m.reason else "") for m in result.moves]
    lines.append(f"total {result.total_time:.2f} s (simulated)"
                 + (f"; {result.message}" if result.message else ""))
    return lines
