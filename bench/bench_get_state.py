"""Round trip of the arm's get_state against a bare std_srvs/Trigger server, same run, same client."""
from common import RosClient, latencies, row, running

from acti_msgs.srv import GetState
from std_srvs.srv import Trigger

N = 300


def main() -> None:
    ros = RosClient()
    with running("bench.trigger_server"), running("acti_middle_node"):
        bare = latencies(lambda: ros.call(Trigger, "/bare_trigger/trigger"), N)
        arm = latencies(lambda: ros.call(GetState, "/acti_middle_node/get_state"), N)
    print(f"round trip over DDS, {N} calls each (arm idle, simulation at real time)")
    print(row("std_srvs/Trigger (bare baseline)", bare))
    print(row("acti_middle_node/get_state", arm, bare))
    ros.close()


if __name__ == "__main__":
    main()
