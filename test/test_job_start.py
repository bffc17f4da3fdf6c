"""What a job says when it starts: a parameters file none of whose sections is one of its
nodes is named with its sections and the job's nodes; the banner says when it serves."""
from acti_bringup.serving import usage
from ros_harness import NodeProcess, TEST_RATE, wait_until

ELSEWHERE = """\
/robot1/vehicle_node:
  ros__parameters:
    queue_size: 8
acti_middle_node:
  ros__parameters:
    queue_size: 8
"""
MATCHING = """\
/**/vehicle_node:
  ros__parameters:
    queue_size: 9
"""


def test_a_parameters_file_for_other_nodes_is_named_and_one_that_matches_is_not(tmp_path):
    elsewhere, matching = tmp_path / "elsewhere.yaml", tmp_path / "matching.yaml"
    elsewhere.write_text(ELSEWHERE)
    matching.write_text(MATCHING)
    for kept in usage.CACHE.glob("vehicle_node.node.VehicleNode-*.txt"):
        kept.unlink()
    job = NodeProcess("vehicle_node", str(tmp_path / "job.log"), TEST_RATE, namespace="/robot3",
                      params_file=(str(elsewhere), str(matching)))
    try:
        assert wait_until(lambda: "READY: /robot3/vehicle_node serving" in job.log(), 120), job.log()
    finally:
        job.stop()
    warned = [line for line in job.log().splitlines() if "none of its sections" in line]
    assert len(warned) == 1, job.log()
    assert warned[0].startswith("[WARN]") and (
        f"{elsewhere}: none of its sections (/robot1/vehicle_node, acti_middle_node) is a node "
        "of this job (/robot3/vehicle_node)") in warned[0], warned[0]
    # the job kept the list `--help` prints, with the declared defaults (the file set 9)
    kept = list(usage.CACHE.glob("vehicle_node.node.VehicleNode-*.txt"))
    assert len(kept) == 1 and "    queue_size: 32 [1 … 100000]" in kept[0].read_text()
