"""The main job while DDS participants come and go, as every `ros2` command is one: two one-shot
clients (start, call a service once, end) at a time, beside a /clock listener, in rounds (quiet;
the clients call the job's get_state; quiet; they call the bare Trigger …) so that drift cancels.
Each round: get_state and the bare Trigger, interleaved (bare, get_state …), p50 / p99 / max
and the calls over 100 ms; the control loop's reports of falling behind its schedule (the job's
log); the longest /clock silence as received here (DDS source timestamps).

Fast DDS sleeps a third of a second inside a send when it meets the shared-memory port of a
starting or ending participant (`acti_bringup.serving.outbox`). Before the outbox, rclpy held the
GIL through that send and the whole job froze: at 916d525, two 25 s runs gave get_state at most
343 and 667 ms, 4 and 7 calls over 100 ms, /clock silent for ~335 ms 4 and 8 times."""
import re
import time

import numpy as np
from rosgraph_msgs.msg import Clock

from common import RosClient, bare_call, interleaved, p, running

from acti_bringup.harness import FELL_BEHIND, OneShotClients
from acti_msgs.srv import GetState
from std_srvs.srv import Trigger

from common import BARE

ROUNDS = 2
ROUND_S = 20.0
GET_STATE = "/acti_middle_node/get_state"


def main() -> None:
    ros = RosClient()
    sent: list[float] = []
    ros.node.create_subscription(Clock, "/clock",
                                 lambda _m, info: sent.append(info["source_timestamp"] * 1e-9), 100)
    calls = [("bare Trigger", bare_call(ros)),
             ("get_state", lambda: ros.call(GetState, GET_STATE))]
    with running("bench.trigger_server"), running("acti_bringup", "clock_rate_hz:=250.0") as job:
        ros.call(GetState, GET_STATE)
        assert ros.spin_until(lambda: len(sent) > 250, 30.0), "no /clock"
        print(f"main job, /clock at 250 Hz listened to; rounds of {ROUND_S:.0f} s, quiet or with "
              "two one-shot clients at a time; round trips p50 / p99 / max in ms")
        for _ in range(ROUNDS):
            for churn in (None, (GetState, GET_STATE), None, (Trigger, BARE)):
                report(churn, *one_round(ros, job, calls, sent, churn))
    ros.close()


def one_round(ros: RosClient, job, calls, sent: list[float], churn: tuple | None):
    """One round; `churn`: (service type, name) the one-shot clients call, None for none."""
    clients = OneShotClients(*churn) if churn else None
    seen, t0 = len(job.log()), time.time()
    samples: dict[str, list[float]] = {name: [] for name, _ in calls}
    try:
        deadline = time.monotonic() + ROUND_S
        while time.monotonic() < deadline:
            if clients:
                clients.keep()
            for name, sample in interleaved(calls, 20, warmup=0).items():
                samples[name].extend(sample)
            ros.spin_until(lambda: False, 0.01, period=0.01)
    finally:
        if clients:
            clients.end()
    ros.spin_until(lambda: False, 0.5)              # the round's last /clock messages arrive
    stamps = np.array([s for s in sent if s >= t0])
    falls = [int(ms) for ms in re.findall(FELL_BEHIND, job.log()[seen:])]
    gap = float(np.diff(stamps).max()) * 1e3 if len(stamps) > 1 else float("inf")
    return ({k: np.array(v) for k, v in samples.items()}, clients.started if clients else 0,
            falls, gap)


def report(churn: tuple | None, samples: dict[str, np.ndarray], started: int, falls: list[int],
           gap: float) -> None:
    what = f"{started} one-shot -> {churn[1].rsplit('/', 1)[1]}" if churn else "quiet"
    text = "  ".join(f"{name} {p(s, 50):.3f} / {p(s, 99):.2f} / {s.max() * 1e3:.1f}"
                     f" (>100 ms: {(s > 0.1).sum()})" for name, s in samples.items())
    bare, state = samples["bare Trigger"], samples["get_state"]
    print(f"{what:<28} {text}  p99 ratio {p(state, 99) / p(bare, 99):.2f}; loop fell behind: "
          f"{falls or 'never'}; longest /clock silence {gap:.0f} ms")


if __name__ == "__main__":
    main()
