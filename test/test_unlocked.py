"""What the process sends leaves through the outbox, without the GIL
(`acti_bringup.serving.outbox`, `acti_bringup.serving.unlocked`): the outbox keeps order and
never makes its callers wait, even while a send is held up; over real DDS, responses and
messages arrive as sent (converted when handed over, so later changes to a message do not
reach it), a header rclpy's layout does not explain goes through rclpy, a message of another
type is refused, and rcl's sends are called with the GIL released."""
from __future__ import annotations

import ctypes
import threading
import time

import pytest
from acti_msgs.msg import LimitValue
from acti_msgs.srv import GetSoftLimitJoint, SetSpeedJoint
from std_msgs.msg import Float64MultiArray, String
from std_srvs.srv import Trigger

from acti_bringup.serving.outbox import Outbox, unlocked_publish
from acti_bringup.serving.responses import LateResponses, UnlockedSender
from acti_bringup.serving.unlocked import header_address, rcl, respond
from ros_harness import wait_until


def test_the_outbox_sends_in_order_on_its_own_thread():
    sent: list = []
    outbox = Outbox(print)
    for i in range(100):
        outbox.put(lambda i=i: sent.append((i, threading.current_thread().name)))
    assert wait_until(lambda: len(sent) == 100, 10.0)
    assert sent == [(i, "dds-out") for i in range(100)]
    outbox.stop()


def test_a_held_up_send_never_holds_up_the_callers():
    """A send DDS holds (here: one that waits for an event) keeps the outbox's thread; whoever
    hands it messages meanwhile (the control loop) goes on at once."""
    release, sent = threading.Event(), []
    outbox = Outbox(print)
    outbox.put(release.wait)
    t0 = time.monotonic()
    for i in range(1000):
        outbox.put(lambda i=i: sent.append(i))
    assert time.monotonic() - t0 < 1.0 and sent == []
    release.set()
    assert wait_until(lambda: len(sent) == 1000, 10.0)
    outbox.stop()


def test_beyond_its_capacity_the_outbox_drops_the_oldest_and_says_so(monkeypatch):
    monkeypatch.setattr(Outbox, "CAPACITY", 10)
    release, sent, discarded, log = threading.Event(), [], [], []
    outbox = Outbox(log.append)
    outbox.put(release.wait)
    assert wait_until(lambda: not outbox._items, 10.0)    # the blocking send is under way
    for i in range(15):
        outbox.put(lambda i=i: sent.append(i), lambda i=i: discarded.append(i))
    release.set()
    assert wait_until(lambda: len(sent) == 10, 10.0)
    assert sent == list(range(5, 15)) and discarded == list(range(5))
    assert wait_until(lambda: log, 10.0) and "5 messages dropped" in log[0]
    outbox.stop()


def test_a_failed_send_is_one_log_line_and_the_outbox_goes_on():
    log, sent = [], []

    def broken() -> None:
        raise RuntimeError("publisher's handle is not valid")
    outbox = Outbox(log.append)
    for _ in range(3):
        outbox.put(broken)
    outbox.put(lambda: sent.append(1))
    assert wait_until(lambda: sent, 10.0)
    assert log == ["a message could not be sent: RuntimeError: publisher's handle is not valid"]
    outbox.stop()


def test_rcl_is_found_where_rclpy_loaded_it():
    assert rcl() is not None


def test_the_one_call_send_is_built():
    """`make setup` compiles acti_bringup/serving/_respond.c (setup.py's extension, built in
    place); without it every response would leave through the outbox."""
    assert respond is not None, "the C extension is not built: run `make setup`"


def test_responses_reach_the_client_through_rcl(ros, events_loop):
    node, loop = events_loop
    outbox, headers = Outbox(print), []

    def limits(_request, response):
        response.soft_limit = [LimitValue(lower=-1.5 - i, upper=2.5 + i) for i in range(7)]
        response.return_id.comment = "ok"
        return response
    service = node.create_service(GetSoftLimitJoint, "~/limits", limits)
    sender = UnlockedSender(service)

    def send_response(response, header) -> None:
        headers.append(header_address(header))
        if sender.answer_now(response, header) is None:     # a new client: through the outbox
            prepared = sender.prepare(response, header)
            outbox.put(prepared.send, prepared.discard)
    service.send_response = send_response
    loop.start()
    for _ in range(20):
        r = ros.call(GetSoftLimitJoint, "/spin_loop_test/limits")
        assert [(x.lower, x.upper) for x in r.soft_limit] == [(-1.5 - i, 2.5 + i) for i in range(7)]
        assert r.return_id.comment == "ok"
    assert len(headers) == 20 and None not in headers       # never rclpy's send
    outbox.stop()


def test_a_client_answered_once_is_answered_from_the_serving_thread(ros, events_loop):
    """The first response to a client leaves from the outbox (DDS may hold it while it meets the
    client), the next ones at once from the serving thread (no hand-over to pay), in one call of
    the C extension `make setup` builds; all without the GIL."""
    node, loop = events_loop
    threads: list[str] = []

    class Recording(UnlockedSender):
        def answer_now(self, response, header):
            answered = super().answer_now(response, header)
            if answered is not None:
                threads.append(threading.current_thread().name)
            return answered

        def prepare(self, response, header):
            prepared = super().prepare(response, header)

            def send() -> bool:
                threads.append(threading.current_thread().name)
                return prepared.send()
            return prepared._replace(send=send)
    node.create_service(Trigger, "~/ping", lambda _q, response: response)
    outbox = Outbox(print)
    LateResponses(print, outbox, Recording).serve([node])
    loop.start()
    for _ in range(5):
        ros.call(Trigger, "/spin_loop_test/ping")
    assert threads == ["dds-out"] + ["test-events"] * 4
    outbox.stop()


def test_a_header_that_is_not_rclpys_is_not_read():
    class Header:
        sequence_number = 1
    assert header_address(Header()) is None
    assert header_address(object()) is None


def test_messages_arrive_as_they_were_when_handed_over(ros):
    node = ros.rclpy.create_node("unlocked_publisher")
    got: list = []
    sub = ros.node.create_subscription(Float64MultiArray, "/unlocked_topic",
                                       lambda m: got.append(list(m.data)), 10)
    outbox = Outbox(print)
    try:
        publisher = node.create_publisher(Float64MultiArray, "/unlocked_topic", 10)
        publish = unlocked_publish(outbox, publisher)
        assert ros.spin_until(lambda: publisher.get_subscription_count() > 0, 10.0)
        msg = Float64MultiArray()
        for i in range(5):
            msg.data = [float(i), 0.5]           # one message, filled in place each time
            publish(msg)
        assert ros.spin_until(lambda: len(got) == 5, 10.0), got
        assert got == [[float(i), 0.5] for i in range(5)]
        with pytest.raises(TypeError):
            publish(String(data="another type"))
    finally:
        outbox.stop()
        ros.node.destroy_subscription(sub)
        node.destroy_node()


def test_the_gil_is_free_while_rcl_sends():
    """rcl's sends are called as plain C functions, which ctypes calls with the GIL released: a
    Python thread runs on during such a call (here a 1 s usleep), and never during the same
    call made with the GIL held (as rclpy makes its calls). Judged by when the thread ran, in
    the middle half of the call: counted over the whole call, the thread's counts depended on
    the CPU a busy machine gave it and on the switch interval it may run before the call
    starts (866 773 against 10 x 102 549 in one full run)."""
    def ran_during(usleep) -> int:
        """How often the other thread ran (in ms it was seen in) within the middle half of a
        1 s call of `usleep`: the call began at least 1 s before it returned."""
        usleep.argtypes = (ctypes.c_uint,)
        seen, stop = [0.0], threading.Event()

        def note():
            while not stop.is_set():
                now = time.monotonic()
                if now - seen[-1] > 0.001:
                    seen.append(now)
        t = threading.Thread(target=note)
        t.start()
        time.sleep(0.05)
        usleep(1_000_000)
        returned = time.monotonic()
        stop.set()
        t.join()
        return sum(returned - 0.75 <= s <= returned - 0.25 for s in seen)
    assert ran_during(ctypes.CDLL(None).usleep) > 0
    assert ran_during(ctypes.PyDLL(None).usleep) == 0
    lib = rcl()
    for send in (lib.send_response, lib.publish, lib.publish_feedback, *lib.action_answers.values()):
        assert not send._flags_ & ctypes._FUNCFLAG_PYTHONAPI



def test_a_response_answered_again_reuses_its_kept_c_message(ros, events_loop):
    """A callback that answers an unchanged reply with the same response object (as the
    operations' handlers do) is answered from the C message kept for it; switching between
    responses frees the older one and sends the right values every time."""
    node, loop = events_loop
    responses: dict[int, SetSpeedJoint.Response] = {}

    def one_per_ratio(request, fresh):
        if request.spd_ratio not in responses:
            fresh.return_id.comment = f"ratio {request.spd_ratio}"
            responses[request.spd_ratio] = fresh
        return responses[request.spd_ratio]
    node.create_service(SetSpeedJoint, "~/kept", one_per_ratio)
    outbox = Outbox(print)
    LateResponses(print, outbox).serve([node])
    loop.start()
    for ratio in (1, 1, 1, 2, 2, 1, 1, 3, 3, 1):
        r = ros.call(SetSpeedJoint, "/spin_loop_test/kept", spd_ratio=ratio)
        assert r.return_id.comment == f"ratio {ratio}"
    outbox.stop()


def test_a_known_client_given_a_response_of_another_type_gets_one_log_line(ros, events_loop):
    """A callback that returns another type to a client answered before: nothing is sent (as
    rclpy refuses it), one log line says why, and the service goes on answering."""
    node, loop = events_loop
    wrong = [False]
    node.create_service(Trigger, "~/typed",
                        lambda _q, response: String(data="x") if wrong[0] else response)
    outbox, log = Outbox(print), []
    LateResponses(log.append, outbox).serve([node])
    loop.start()
    ros.call(Trigger, "/spin_loop_test/typed")                # the client is known from now on
    wrong[0] = True
    ros._clients["/spin_loop_test/typed"].call_async(Trigger.Request())     # the same client
    assert ros.spin_until(lambda: log, 10.0)
    assert log == ["a response to /spin_loop_test/typed could not be sent: TypeError: expected a "
                   "Trigger_Response, got a String"]
    wrong[0] = False
    ros.call(Trigger, "/spin_loop_test/typed")
    outbox.stop()
