"""Control-plane round trips of the main job (both nodes, one world, idle) against a bare
std_srvs/Trigger server: get_state and every getter of both nodes, each interleaved with the
baseline (bare, getter, bare, getter …); then the main job's CPU use while idle (over 20 s,
3 s after the last call)."""
import time

from common import (RosClient, against, bare_call, idle_cpu_percent, interleaved, running, table,
                    worst_ratios)

from acti_middle_node.operations import OPERATIONS as ARM_OPERATIONS
from vehicle_node.operations import OPERATIONS as BASE_OPERATIONS

N = 200
GETTERS = [(f"/{node}/{op.name}", op.srv_type)
           for node, ops in (("acti_middle_node", ARM_OPERATIONS), ("vehicle_node", BASE_OPERATIONS))
           for op in ops if op.name.startswith("get_")]


def main() -> None:
    ros = RosClient()
    with running("bench.trigger_server"), running("acti_bringup") as job:
        getters = [(name, lambda s=srv_type, n=name: ros.call(s, n)) for name, srv_type in GETTERS]
        samples = interleaved(against(("bare Trigger", bare_call(ros)), getters), N)
        time.sleep(3.0)          # the calls' tail (DDS acknowledgements, collections) ends
        cpu = idle_cpu_percent(job.proc.pid, seconds=20.0)
    table(f"round trip over DDS, {N} rounds of (bare, getter) for each of {len(GETTERS)} getters; "
          f"main job idle, simulation at real time", samples, "bare Trigger")
    p50, p99 = worst_ratios(samples, "bare Trigger")
    print(f"worst getter ratio: p50 {p50:.2f}  p99 {p99:.2f}   (goal <= 1.3)")
    print(f"main job (python -m acti_bringup) idle CPU: {cpu:.1f} % of one core   (goal <= 10 %)")
    ros.close()


if __name__ == "__main__":
    main()
