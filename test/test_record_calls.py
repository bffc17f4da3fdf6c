"""Recorded calls paired and ordered by the server's stamps, and the comparison of answers (what
is normalised, what is measured, what must be exactly equal)."""
import math

from acti_record.calls import (REQUEST_RECEIVED, RESPONSE_SENT, Event, differences,
                               largest_deviation, pair, service_of)


def event(service: str, kind: int, client: int, stamp: int, message: str) -> Event:
    return Event(service, "pkg/srv/S", kind, (b"gid", client), stamp, message)


def test_events_pair_into_calls_in_the_order_the_server_took_them():
    # the recorder received B's events first; the server took A's request first
    events = [event("/b", REQUEST_RECEIVED, 1, 30, "b?"), event("/b", RESPONSE_SENT, 1, 40, "b!"),
              event("/a", RESPONSE_SENT, 7, 20, "a!"), event("/a", REQUEST_RECEIVED, 7, 10, "a?"),
              event("/a", REQUEST_RECEIVED, 8, 50, "unanswered?")]
    calls = pair(events)
    assert [(c.service, c.request, c.response) for c in calls] == [
        ("/a", "a?", "a!"), ("/b", "b?", "b!"), ("/a", "unanswered?", None)]


def test_service_event_topics_name_their_service_and_type():
    assert service_of("/arm/servo_on/_service_event", "acti_msgs/srv/ServoON_Event") == \
        ("/arm/servo_on", "acti_msgs/srv/ServoON")
    assert service_of("/arm/move/_action/send_goal/_service_event",
                      "acti_msgs/action/Move_SendGoal_Event") == \
        ("/arm/move/_action/send_goal", "acti_msgs/action/Move_SendGoal")
    assert service_of("/joint_states", "sensor_msgs/msg/JointState") is None


def test_answers_differ_where_they_should_and_nowhere_else():
    recorded = {"return_id": {"id": 0, "comment": ""}, "motion_id": 3, "pos": [10.0, 20.0],
                "result": {"stamp": {"sec": 1, "nanosec": 2}, "duration": 1.5, "state": 1}}
    same = {"return_id": {"id": 0, "comment": ""}, "motion_id": 9, "pos": [10.01, 19.99],
            "result": {"stamp": {"sec": 7, "nanosec": 0}, "duration": 2.5, "state": 1}}
    assert differences(recorded, same) == []
    other = {**same, "pos": [10.2, 20.0], "return_id": {"id": -4, "comment": "servo is off"},
             "result": {"state": 3}}
    assert differences(recorded, other) == [
        "response.return_id.id: recorded 0, replayed -4",
        "response.return_id.comment: recorded '', replayed 'servo is off'",
        "response.pos[0]: recorded 10.0, replayed 10.2",
        "response.result.state: recorded 1, replayed 3"]
    assert differences([1, 2], [1, 2, 3]) == ["response: recorded [1, 2], replayed [1, 2, 3]"]
    assert differences({"x": 1.0}, {"x": 1.04}, abs_tol=0.01) == [
        "response.x: recorded 1.0, replayed 1.04"]
    assert differences({"state": 3, "completed": True}, {"state": 1, "completed": False},
                       abs_tol=100.0) == ["response.state: recorded 3, replayed 1",
                                          "response.completed: recorded True, replayed False"]
    assert math.isclose(largest_deviation(recorded, other), 0.2)      # pos[0]; stamps not
    assert largest_deviation({"motion_id": 3, "ok": True}, {"motion_id": 4, "ok": False}) == 0.0
