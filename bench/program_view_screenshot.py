"""docs/program_view.png: the live view of a running main job while a RoboLine program
(examples/programs/palletising.rbl) stands at a breakpoint: the Program panel shows its lines
around the current one (▶) and its breakpoints (●).

    python bench/program_view_screenshot.py [OUT.png]
"""
from __future__ import annotations

import sys
from pathlib import Path

from common import Actions, RosClient, save_page, view_page

from acti_msgs import srv
from acti_msgs.action import RunProgram

ARM = "/acti_middle_node/"
ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "programs" / "palletising.rbl"
BREAK_AT = 22            # the WAIT after MOVE L, target: held there the second time round


def main() -> None:
    out = sys.argv[1] if len(sys.argv) > 1 else str(ROOT / "docs" / "program_view.png")
    ros = RosClient()
    with view_page(ros, 1100, 820, "real_time_factor:=4.0") as (_job, browser):
        assert ros.call(srv.ServoON, ARM + "servo_on").return_id.id == 0
        programs = Actions(ros, RunProgram, ARM + "run_program")
        handle = programs.send(source=EXAMPLE.read_text(), source_name=EXAMPLE.name,
                               points=EXAMPLE.with_suffix(".pts").read_text(),
                               breakpoints=[BREAK_AT])
        debug = lambda: ros.call(srv.ProgramDebug, ARM + "program_debug",  # noqa: E731
                                 command=srv.ProgramDebug.Request.SET, lines=[])
        for _ in range(2):             # the second stop: a placed part's trail in view
            assert ros.spin_until(lambda: debug().state == "at breakpoint", 120.0)
            if _ == 0:
                ros.call(srv.ProgramDebug, ARM + "program_debug",
                         command=srv.ProgramDebug.Request.CONTINUE)
                assert ros.spin_until(lambda: debug().state != "at breakpoint", 30.0)
        ros.spin_until(lambda: False, 2.0)          # the panel refreshes
        save_page(browser, out)
        programs.cancel(handle)
    ros.close()
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
