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
