"""Control-plane round trips of the main job (both nodes, one world, idle) against a bare
std_srvs/Trigger server: get_state and every getter of both nodes, each in blocks of its own
alternating with the baseline (bare, getter, bare, getter …), one block per getter in each of
BLOCKS passes through them all, pooled; then one round through all of
them (bare, getter 1, bare, getter 2 …, every service cold); then the main job's CPU use while
idle (over 20 s, 3 s after the last call); last, every getter against a bare server answering
the same reply (`trigger_server.py replay`): the ROS layer's own cost, without the larger
message's conversions that the Trigger baseline leaves in; and that bare node's replies against
the bare Trigger: the messages' own cost, and how far a node that adds nothing gets."""
import time

import numpy as np

from common import (RosClient, against, answered, bare_call, bare_trigger_answers,
                    idle_cpu_percent, interleaved, p, paired, running, table, worst_ratios)

from bench.trigger_server import GETTERS, REPLAY

N = 500
BLOCKS = 5       # the N alternations of a getter: in this many blocks, spread over the run
ROUNDS = 100


def main() -> None:
    ros = RosClient()
    with running("bench.trigger_server"), running("acti_bringup") as job:
        bare_trigger_answers(ros)
        getters = [(name, lambda s=srv_type, n=name: ros.call(s, n)) for name, srv_type in GETTERS]
        pairs = paired(bare_call(ros), getters, N, rounds=BLOCKS)
        rounds = interleaved(against(("bare Trigger", bare_call(ros)), getters), ROUNDS)
        time.sleep(3.0)          # the calls' tail (DDS acknowledgements, collections) ends
        cpu = idle_cpu_percent(job.proc.pid, seconds=20.0)
        with running("bench.trigger_server", args=("replay",)):
            for name, srv_type in GETTERS:
                answered(ros, srv_type, REPLAY + name)
            replays = {name: lambda s=srv_type, n=name: ros.call(s, REPLAY + n)
                       for name, srv_type in GETTERS}
            same = paired(replays, getters, N, rounds=BLOCKS)
            bare_same = paired(bare_call(ros), list(replays.items()), N, rounds=BLOCKS)
    table(f"round trip over DDS, {N} alternations (bare, getter) for each of {len(GETTERS)} "
          f"getters in {BLOCKS} blocks spread over the run; main job idle, simulation at real "
          "time", pairs, "bare Trigger")
    p50, p99 = worst_ratios(pairs)
    print(f"worst getter ratio: p50 {p50:.2f}  p99 {p99:.2f}   (goal <= 1.3)")
    medians = sorted(p(s, 50) / p(base, 50) for base, s in pairs.values())
    print(f"median getter ratio p50 {np.median(medians):.2f}; {sum(r <= 1.3 for r in medians)} "
          f"of {len(medians)} getters <= 1.3 (one run's worst is the largest of {len(medians)} "
          "noisy ratios: the median is what moves with the code)")
    bare = rounds.pop("bare Trigger")
    cold = sorted(p(s, 50) / p(bare, 50) for s in rounds.values())
    print(f"{ROUNDS} rounds through all {len(GETTERS)} getters (bare, getter 1, bare, getter 2 …: "
          f"each service called once in {2 * len(GETTERS)} calls, cold): p50 ratios "
          f"{cold[0]:.2f} … {cold[-1]:.2f}, median {cold[len(cold) // 2]:.2f}")
    print(f"main job (python -m acti_bringup) idle CPU: {cpu:.1f} % of one core   (goal <= 10 %)")
    table(f"the same getters against a bare server answering the same reply, {N} alternations "
          f"each in {BLOCKS} blocks", same, "bare replay", "each getter's reply")
    same_p50 = sorted(p(s, 50) / p(base, 50) for base, s in same.values())
    p50, p99 = worst_ratios(same)
    print(f"vs a bare node answering the same messages: median getter p50 "
          f"{np.median(same_p50):.2f}, worst p50 {p50:.2f}  p99 {p99:.2f}; "
          f"{sum(r <= 1.3 for r in same_p50)} of {len(same_p50)} getters <= 1.3")
    table(f"that bare node's replies against the bare Trigger, {N} alternations each in {BLOCKS} "
          "blocks: what the messages cost", bare_same, "bare Trigger")
    bare_p50 = sorted(p(s, 50) / p(base, 50) for base, s in bare_same.values())
    p50, p99 = worst_ratios(bare_same)
    print(f"a bare node answering the getters' replies vs the bare Trigger: median p50 "
          f"{np.median(bare_p50):.2f}, worst p50 {p50:.2f}  p99 {p99:.2f}; "
          f"{sum(r <= 1.3 for r in bare_p50)} of {len(bare_p50)} <= 1.3")
    ros.close()


if __name__ == "__main__":
    main()
