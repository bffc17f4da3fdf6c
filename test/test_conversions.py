"""Core values → ROS messages (`acti_bringup.serving.conversions.fill`): nested messages built once per
value and shared, and a changed value built anew."""
from acti_msgs.srv import GetFeedbackPosCartesian, GetSoftLimitJoint

from acti_bringup.serving.conversions import fill

LIMITS = [(170.0, -170.0), (120.0, -120.0)]


def test_the_same_limits_give_the_same_messages_and_new_limits_new_ones():
    a, b, c = (GetSoftLimitJoint.Response() for _ in range(3))
    fill(a, {"soft_limit": LIMITS})
    fill(b, {"soft_limit": [tuple(x) for x in LIMITS]})
    fill(c, {"soft_limit": [(170.0, -170.0), (121.0, -120.0)]})
    assert [(v.upper, v.lower) for v in a.soft_limit] == LIMITS
    assert b.soft_limit is a.soft_limit
    assert [(v.upper, v.lower) for v in c.soft_limit] == [(170.0, -170.0), (121.0, -120.0)]


def test_a_nested_message_with_an_array_inside_is_built_from_lists_tuples_or_arrays():
    import numpy as np
    hg = [1.0, 0.0, 0.0, 10.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0]
    a, b = GetFeedbackPosCartesian.Response(), GetFeedbackPosCartesian.Response()
    fill(a, {"pos": (hg, 30.0, 1)})
    fill(b, {"pos": (np.array(hg), np.float64(30.0), 1)})
    for r in (a, b):
        assert list(r.pos.car_pos) == hg and r.pos.elbow == 30.0 and r.pos.struct_flag == 1


class _Node:
    """What an operation's handler needs of its node: a logger."""

    def __init__(self) -> None:
        self.errors: list[str] = []

    def get_logger(self):
        return self

    def error(self, text: str) -> None:
        self.errors.append(text)


def test_an_unchanged_reply_is_answered_with_the_response_that_carried_it():
    """A getter asked again while nothing changed answers with the same response object (its C
    message is kept by the sender: no filling, no conversion); a changed reply gets a response
    of its own."""
    from acti_bringup.serving.adapter import Operation, _handler
    from acti_middle_node.node import write_return_id
    from acti_motion.replies import Reply
    limits = {"soft_limit": LIMITS}
    node = _Node()
    handle = _handler(node, Operation("get_soft_limit_joint", GetSoftLimitJoint),
                      lambda: Reply(values=limits["soft_limit"] and dict(limits)), write_return_id)
    ask = lambda: handle(GetSoftLimitJoint.Request(), GetSoftLimitJoint.Response())  # noqa: E731
    first = ask()
    assert ask() is first and ask() is first
    limits["soft_limit"] = [(170.0, -170.0), (121.0, -120.0)]
    changed = ask()
    assert changed is not first
    assert [(v.upper, v.lower) for v in changed.soft_limit] == limits["soft_limit"]
    assert ask() is changed
    limits["soft_limit"] = LIMITS
    again = ask()
    assert again is not first and [(v.upper, v.lower) for v in again.soft_limit] == LIMITS


def test_a_reply_key_is_the_same_for_the_same_values_in_any_container_and_none_without_one():
    """The memo's key: lists, tuples and arrays of the same numbers give the same key, other
    numbers another, a None value is a value, and a value with no hashable copy gives no key
    (such a reply is never answered from the memo)."""
    import numpy as np
    from acti_bringup.serving.conversions import reply_key
    key = reply_key(0, "", {"soft_limit": LIMITS, "n": 1})
    assert key == reply_key(0, "", {"soft_limit": [list(x) for x in LIMITS], "n": 1})
    assert key == reply_key(0, "", {"soft_limit": np.array(LIMITS), "n": 1})
    assert hash(key) == hash(reply_key(0, "", {"soft_limit": tuple(LIMITS), "n": 1}))
    assert key != reply_key(0, "", {"soft_limit": [(170.0, -170.0), (121.0, -120.0)], "n": 1})
    assert key != reply_key(-3, "", {"soft_limit": LIMITS, "n": 1})
    assert key != reply_key(0, "why", {"soft_limit": LIMITS, "n": 1})
    assert reply_key(0, "", {"a": None}) == (0, "", (("a", None),))
    assert reply_key(0, "", {"a": {"b": 1}}) is None
    assert reply_key(0, "", {"a": [1, {"b": 1}]}) is None


def test_requests_are_read_as_core_values_by_readers_decided_per_type():
    """A request's fields as the core takes them (`request_reader`): a nested message as the
    tuple of its fields, its array a list of floats; a sequence of messages a list of tuples;
    a scalar as it is. `to_core` reads any message the same way."""
    from acti_msgs.msg import CarPosWithElbow, LimitValue
    from acti_msgs.srv import MoveLinearCartesianRel, SetSoftLimitJoint, SetSpeedJoint
    from acti_bringup.serving.conversions import request_reader, to_core
    hg = [1.0, 0.0, 0.0, 20.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0]
    move = MoveLinearCartesianRel.Request(car_point=CarPosWithElbow(car_pos=hg, elbow=30.0,
                                                                    struct_flag=2))
    read = request_reader(MoveLinearCartesianRel.Request)(move)
    assert read == {"car_point": (hg, 30.0, 2)} and type(read["car_point"][0]) is list
    limits = SetSoftLimitJoint.Request(soft_limit=[LimitValue(upper=170.0, lower=-170.0),
                                                   LimitValue(upper=120.0, lower=-120.0)])
    assert request_reader(SetSoftLimitJoint.Request)(limits) == {"soft_limit": LIMITS}
    assert request_reader(SetSpeedJoint.Request)(SetSpeedJoint.Request(spd_ratio=40)) == \
        {"spd_ratio": 40}
    assert to_core(move.car_point) == (hg, 30.0, 2)
    assert to_core(limits) == (LIMITS,)
