"""The live view in a real browser: the main job serves it, Debian's headless Chromium opens it
(software WebGL), the robot is drawn and follows the arm, and STOP pressed in the page stops the
arm over the same control path as the ~/stop service (checked over ROS)."""
import re

import numpy as np
import pytest
from acti_msgs import srv
from acti_msgs.msg import ArmState
from sensor_msgs.msg import JointState

from acti_bringup.visual.browser import open_browser, robot_pixels, screenshot
from ros_harness import node_fixture, wait_until

robot = node_fixture("acti_bringup", "view_port:=0")
ARM = "/acti_middle_node/"
START = [0.0, 30.0, 0.0, -60.0, 0.0, 60.0, 0.0]
MOVED = [90.0, 60.0, 0.0, -30.0, 0.0, 30.0, 0.0]
@pytest.fixture(scope="module")
def page(robot):
    assert wait_until(lambda: "live view: " in robot.log(), 60.0), robot.log()
    url = re.search(r"live view: (\S+)", robot.log()).group(1)
    driver = open_browser(800, 500)
    try:
        driver.get(url)
        yield driver
    finally:
        driver.quit()


def subscription(ros, msg_type, topic):
    latest = []
    sub = ros.node.create_subscription(msg_type, topic, latest.append, 10)
    yield latest
    ros.node.destroy_subscription(sub)


@pytest.fixture(scope="module")
def arm_state(ros, robot):
    yield from subscription(ros, ArmState, ARM + "state")


@pytest.fixture(scope="module")
def joint_states(ros, robot):
    yield from subscription(ros, JointState, "/joint_states")


def call(ros, name, srv_type, **fields):
    reply = ros.call(srv_type, ARM + name, **fields)
    assert reply.return_id.id == 0, reply.return_id.comment
    return reply


def page_text(driver) -> str:
    return driver.execute_script("return document.body.innerText")


def saved(path, image: np.ndarray) -> np.ndarray:
    """Keep the screenshot next to the test's log, for a person to look at."""
    import matplotlib.image as mpimg
    mpimg.imsave(str(path), image)
    return image


def test_page_draws_the_robot_and_follows_the_arm(ros, page, arm_state, tmp_path):
    assert wait_until(lambda: robot_pixels(screenshot(page)).sum() > 300, 90.0, period=0.5), \
        "the robot was not drawn"
    image = saved(tmp_path / "before.png", screenshot(page))
    assert image.std() > 10, "the page is blank"
    before = robot_pixels(image)
    call(ros, "servo_on", srv.ServoON)
    call(ros, "set_speed_joint", srv.SetSpeedJoint, spd_ratio=60)
    call(ros, "move_ptp_joint_abs", srv.MovePTPJointAbs, joint_points=MOVED)
    assert ros.spin_until(lambda: arm_state and arm_state[-1].motion_id == 0
                          and arm_state[-1].queue_length == 0 and not arm_state[-1].state & 0x02
                          and abs(ros.call(srv.GetFeedbackPosJoint, ARM + "get_feedback_pos_joint")
                                  .pos[0] - 90.0) < 0.5, 60.0)

    def moved() -> bool:
        after = robot_pixels(saved(tmp_path / "after.png", screenshot(page)))
        return after.sum() > 300 and (before ^ after).sum() > 0.3 * before.sum()
    assert wait_until(moved, 60.0, period=0.5), \
        f"the robot's pixels did not move with the arm: see {tmp_path}"
    assert wait_until(lambda: "servo on" in page_text(page), 30.0, period=0.5), page_text(page)


def test_stop_in_the_page_stops_the_arm(ros, page, arm_state, joint_states):
    from selenium.webdriver.common.by import By
    call(ros, "servo_on", srv.ServoON)
    call(ros, "set_speed_joint", srv.SetSpeedJoint, spd_ratio=2)     # J1: 180° in ~100 s
    call(ros, "move_ptp_joint_abs", srv.MovePTPJointAbs, joint_points=[-90.0] + START[1:])
    call(ros, "move_ptp_joint_abs", srv.MovePTPJointAbs, joint_points=START)
    assert ros.spin_until(lambda: arm_state and arm_state[-1].state & 0x02
                          and arm_state[-1].queue_length == 1, 30.0)
    page.find_element(By.XPATH, "//button[normalize-space(.)='STOP arm']").click()

    def at_rest() -> bool:
        s, joints = arm_state[-1], joint_states[-1]
        speeds = [abs(v) for n, v in zip(joints.name, joints.velocity) if n.startswith("joint")]
        return (s.motion_id == 0 and s.queue_length == 0 and not s.state & 0x02
                and max(speeds) < 1e-3)
    assert ros.spin_until(at_rest, 60.0), (arm_state[-1], joint_states[-1])
    assert call(ros, "get_state", srv.GetState).state & 0x02 == 0
    j1 = call(ros, "get_feedback_pos_joint", srv.GetFeedbackPosJoint).pos[0]
    assert j1 > -85.0, f"J1 {j1}°: the arm was not stopped on its way to -90°"
    assert wait_until(lambda: "arm stop: OK" in page_text(page), 30.0, period=0.5), page_text(page)


def canvas_box(driver) -> tuple[int, int, int, int]:
    """(left, top, width, height) of the 3D view in the page: the panel is docked beside it."""
    box = driver.execute_script(
        "const r = document.querySelector('canvas').getBoundingClientRect();"
        "return [r.left, r.top, r.width, r.height];")
    return tuple(round(v) for v in box)


def test_the_view_follows_the_base_3_m_away_and_the_panel_leaves_it_in_sight(ros, page, tmp_path):
    """The camera stayed at the world's origin and the panel covered the right quarter: the
    base was out of sight 2.2 m away. Driven 3 m away, it is in the middle of the view."""
    base = "/vehicle_node/"
    for name, srv_type in (("set_power", srv.VehicleSetPower), ("set_servo", srv.VehicleSetServo)):
        assert ros.call(srv_type, base + name, on_off=True).success
    target = srv.VehicleMoveLinearAbs.Request().pos
    target.x = 3000.0
    assert ros.call(srv.VehicleMoveLinearAbs, base + "move_linear_abs", pos=target).success
    assert ros.spin_until(lambda: ros.call(srv.VehicleGetPosition, base + "get_position")
                          .pos.x > 2990.0, 120.0)
    left, top, width, height = canvas_box(page)
    page_width = page.execute_script("return window.innerWidth")
    assert 0.4 * page_width < width < page_width - 200, (width, page_width)   # the panel beside

    def in_the_middle() -> bool:
        image = saved(tmp_path / "far.png", screenshot(page))
        view = robot_pixels(image[top:top + height, left:left + width], panel_width=0, top=0)
        if view.sum() < 300:
            return False
        ys, xs = np.nonzero(view)
        return abs(xs.mean() / width - 0.5) < 0.25 and abs(ys.mean() / height - 0.5) < 0.25
    assert wait_until(in_the_middle, 60.0, period=0.5), f"the robot is not in view: see {tmp_path}"
