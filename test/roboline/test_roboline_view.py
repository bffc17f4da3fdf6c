"""The live view's program panel: the RoboLine program that runs, its current line (▶) and
breakpoints (●), from a real run held at a breakpoint and a real LiveView."""
from __future__ import annotations

from acti_motion.arm.core import ArmConfig, ArmCore
from acti_motion.executor import MotionExecutor
from acti_motion.programs.run import ProgramRun, Status
from acti_motion.vehicle.core import VehicleCore
from acti_sim.world import URDF_PATH, World
from acti_view.live import LiveView
from acti_view.program import ProgramShown, program_markdown
from acti_view.sample import Reader, WorldSampler
from roboline import Source, compile_source

TEXT = "DIM n AS INT\nFOR n = 1 TO 2\n  PRINT n\nNEXT\nPRINT \"end\"\n"


def test_the_panel_shows_the_current_line_and_the_breakpoints():
    world = World()
    try:
        executor = MotionExecutor(world, real_time_factor=0.0)
        arm = ArmCore(executor, ArmConfig())
        sampler = WorldSampler(executor, every=1)
        sampler.active = True                         # a page is open
        reader = Reader(sampler, arm, VehicleCore(executor))
        program = compile_source(Source(TEXT, "count.rbl"))
        run = ProgramRun(arm, program, breakpoints=[3, 5])
        shown = []

        def panel():
            return ProgramShown(program, run.debugger.line, sorted(run.debugger.breakpoints),
                                run.host.state)
        view = LiveView(reader, {"arm": arm}, URDF_PATH, "127.0.0.1", 0, 25.0, 100,
                        program=panel)

        def step():
            executor.step()
            if run.debugger.waiting:
                view.frames = 0                     # the next update refreshes the panel
                view.update(reader.read())
                shown.append(view.program_panel.content)
                run.debugger.resume()
        run.host.step = step
        try:
            assert view.program_panel.content == "*no RoboLine program runs*"
            assert run.run().status is Status.FINISHED
        finally:
            view.server.stop()
        assert len(shown) == 3
        first = shown[0].splitlines()
        assert first[0] == "**count.rbl**: at breakpoint, line 3; breakpoints 3, 5"
        assert "▶● 3    PRINT n" in first and "   2  FOR n = 1 TO 2" in first
        assert " ● 5  PRINT \"end\"" in first
        assert "▶● 5  PRINT \"end\"" in shown[2].splitlines()
        assert program_markdown(None) == "*no RoboLine program runs*"
    finally:
        world.close()
