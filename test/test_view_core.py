"""The view's ROS-free parts on a real world and real cores: what it samples (control point,
queued targets, panel), the buttons' control path, the PNG snapshot."""
import numpy as np
import pytest

from acti_bringup.visual import snapshot
from acti_bringup.harness import wait_until
from acti_motion.arm.core import ArmConfig, ArmCore
from acti_motion.executor import MotionExecutor
from acti_motion.vehicle.core import VehicleCore
from acti_sim.world import World
from acti_view.controls import CONTROLS, press
from acti_view.live import check_host, panel_text
from acti_view.sample import Reader, WorldSampler, pose_matrix, state_words


@pytest.fixture
def robot():
    world = World()
    executor = MotionExecutor(world, real_time_factor=0.0)
    arm, base = ArmCore(executor, ArmConfig()), VehicleCore(executor)
    sampler = WorldSampler(executor, every=1)
    sampler.active = True                         # a page is open
    yield executor, arm, base, Reader(sampler, arm, base)
    world.close()


def test_the_world_is_sampled_only_while_a_page_is_open(robot):
    executor, _arm, _base, reader = robot
    sampler = reader.sampler
    sampler.active = False
    before = sampler.latest
    executor.step()
    assert sampler.latest is before
    sampler.active = True
    executor.step()
    assert sampler.latest is not before


def control(device, label):
    return next(c for c in CONTROLS if c.device == device and c.label == label)


def test_sample_places_the_control_point_and_the_queued_targets_in_the_world(robot):
    executor, arm, base, reader = robot
    for _ in range(50):
        executor.step()
    s = reader.read()
    base_T = pose_matrix(s.world.base_position, s.world.base_orientation)
    expected = (base_T @ arm.tool_pose(arm.feedback_joints))[:3, 3]
    assert np.allclose(s.control_point, expected, atol=1e-9)
    assert s.world.base_position[2] == pytest.approx(0.1, abs=0.01)      # wheel radius
    arm.servo_on()
    arm.set_speed_joint(50)
    assert arm.move_ptp_joint_rel([20.0] + [0.0] * 6).ok
    assert arm.move_ptp_joint_rel([20.0] + [0.0] * 6).ok
    s = reader.read()
    assert len(s.arm_targets) == 2 and s.arm.queue_length == 2
    q_end = np.radians(ArmConfig().initial_joints_deg) + np.radians([40.0] + [0.0] * 6)
    assert np.allclose(s.arm_targets[-1], (base_T @ arm.tool_pose(q_end))[:3, 3], atol=1e-6)
    executor.step()
    s = reader.read()
    assert s.arm.motion_id == 1 and s.arm.motion_label == "move_ptp_joint_rel"
    assert "moving" in state_words(s.arm.state)
    assert s.base.state == 0x019 and s.base.battery_v > 40.0


def test_stop_button_is_the_stop_operation(robot):
    executor, arm, base, reader = robot
    cores = {"arm": arm, "base": base}
    assert press(control("arm", "STOP arm"), cores).startswith("arm stop: OK: ignored")  # servo off
    assert press(control("arm", "Servo on"), cores) == "arm servo_on: OK"
    arm.set_speed_joint(10)
    arm.move_ptp_joint_rel([60.0] + [0.0] * 6)
    arm.move_ptp_joint_rel([-60.0] + [0.0] * 6)
    for _ in range(100):
        executor.step()
    assert press(control("arm", "STOP arm"), cores) == "arm stop: OK"
    assert not arm.device.queue and arm.device.stopping
    while arm.device.busy:
        executor.step()
    assert arm.device.discarded == 2
    assert press(control("base", "Servo on"), cores).startswith("base set_servo(True): refused")
    assert press(control("base", "Power on"), cores) == "base set_power(True): OK"
    assert press(control("base", "STOP base"), cores) == "base stop: OK"


def test_panel_text_says_states_motion_alarms_and_base(robot):
    executor, arm, base, reader = robot
    text = panel_text(reader.read().arm, reader.read().base)
    for part in ("0x00 servo off", "queued: 0", "motion: none", "alarms: none",
                 "0x019 Unpowered", "x 0 mm", "battery: 5"):
        assert part in text, text


def test_snapshot_writes_a_picture_of_the_robot(tmp_path):
    out = tmp_path / "robot.png"
    snapshot.main([str(out), "--size", "320", "240"])
    import matplotlib.image as mpimg
    image = (mpimg.imread(out)[:, :, :3] * 255).astype(int)
    assert image.shape == (240, 320, 3)
    r, g, b = image[..., 0], image[..., 1], image[..., 2]
    orange = (r > 140) & (g > 0.3 * r) & (g < 0.75 * r) & (b < 0.45 * r)
    assert orange.sum() > 200, "no robot in the picture"


@pytest.mark.parametrize("args, folder, words", [
    (["--joints", "500", "0", "0", "0", "0", "0", "0"], "", "--joints 500 0 0 0 0 0 0: the joints"),
    # were a ZeroDivisionError, a std::bad_alloc abort and a FileNotFoundError traceback
    (["--size", "0", "0"], "", "--size 0 0: both must be positive"),
    (["--size", "100000", "100000"], "", "at most 2073600 px"),
    (["--size", "64", "48"], "no-such-folder", "cannot write")])
def test_snapshot_refuses_what_it_cannot_do_with_one_line(tmp_path, capsys, args, folder, words):
    with pytest.raises(SystemExit) as refused:
        snapshot.main([str(tmp_path / folder / "x.png"), *args])
    assert refused.value.code == 2
    assert words in capsys.readouterr().err


def test_the_odometry_path_and_base_targets_are_drawn_in_the_odom_frame(robot):
    """set_position moves the spec's position frame, not the world: the path (and a target)
    jumped 2 m and ran the wrong way after it."""
    executor, _arm, base, reader = robot
    assert base.set_power(True).ok and base.set_servo(True).ok
    for _ in range(50):
        executor.step()
    before = reader.read().odometry
    assert base.set_position((-1700.0, 800.0, 180.0)).ok
    assert base.move_forward(1500.0).ok
    s = reader.read()
    assert np.allclose(s.odometry, before, atol=1e-6)
    x, y = s.base_targets[-1]                     # 1.5 m ahead of where the base is, in odom
    assert abs(x - before[0] - 1.5) < 1e-3 and abs(y - before[1]) < 1e-3
    assert s.base.position_mm_deg[:2] == pytest.approx((-1700.0, 800.0), abs=1e-6)


def test_trails_restart_when_a_page_opens_after_nobody_looked(robot):
    from acti_sim.world import URDF_PATH
    from acti_view.live import LiveView
    executor, arm, _base, reader = robot
    view = LiveView(reader, {}, URDF_PATH, "127.0.0.1", 0, 25.0, 100)
    try:
        assert view.watching(True)
        assert arm.servo_on().ok and arm.set_speed_joint(50).ok
        assert arm.move_ptp_joint_rel([40.0] + [0.0] * 6).ok
        for _ in range(40):
            for _ in range(10):
                executor.step()
            view.update(reader.read())
        assert len(view.trail) > 5 and view._lines
        assert not view.watching(False)
        for _ in range(50):
            executor.step()                           # moves on, unsampled
        assert view.watching(True) and not view.trail and not view.path and not view._lines
        assert view._restarted_at == reader.sampler.count    # waits for a fresh sample …
        executor.step()
        assert reader.sampler.count > view._restarted_at     # … which the next step takes
        view.update(reader.read())
        assert len(view.trail) == 1
    finally:
        view.server.stop()


def test_live_view_poses_the_robot_at_its_rate_for_a_connected_page(robot):
    """A websocket client speaking viser's own messages stands in for the page here (the
    browser test opens the real one): it says where its camera is, as a page does on connect;
    the view then updates at its rate, and the poses reach it."""
    import threading
    import time

    import msgspec
    import viser
    from viser._messages import ViewerCameraMessage
    from websockets.sync.client import connect

    from acti_sim.world import URDF_PATH
    from acti_view.live import LiveView
    executor, arm, base, reader = robot
    executor.real_time_factor = 1.0
    executor.start()
    view = LiveView(reader, {"arm": arm, "base": base}, URDF_PATH, "127.0.0.1", 0, 25.0, 100)
    view.start()
    received = []
    try:
        url = f"ws://127.0.0.1:{view.server.get_port()}"
        with connect(url, subprotocols=[f"viser-v{viser.__version__}"]) as ws:
            def read():
                try:
                    while True:
                        received.append(len(ws.recv()))
                except Exception:          # closed at the end of the test
                    pass
            threading.Thread(target=read, daemon=True).start()
            camera = ViewerCameraMessage((1.0, 0.0, 0.0, 0.0), (2.0, -2.0, 1.5), 0.8, 0.01, 100.0,
                                         500, 800, (0.0, 0.0, 0.5), (0.0, 0.0, 1.0))
            ws.send(msgspec.msgpack.encode(camera.as_serializable_dict()))
            assert wait_until(lambda: view.frames > 0, 10.0)
            frames0, t0 = view.frames, time.monotonic()
            assert wait_until(lambda: view.frames >= frames0 + 50, 10.0)
            rate = (view.frames - frames0) / (time.monotonic() - t0)
            count = len(received)
            # a robot at rest sends nothing new (POSE_STEP): move the arm
            assert arm.servo_on().ok and arm.set_speed_joint(50).ok
            assert arm.move_ptp_joint_rel([20.0] + [0.0] * 6).ok
            assert wait_until(lambda: len(received) > count, 5.0), "no poses reach the page"
        assert rate >= 20.0, f"{rate:.1f} Hz"
    finally:
        view.close()
        executor.shutdown()


@pytest.mark.parametrize("host, words", [("999.1.1.1", "is no address"),
                                         ("192.0.2.1", "is not an address of this machine")])
def test_a_host_the_view_cannot_listen_on_is_refused_before_serving(host, words):
    """Was: viser's server thread failed to bind and the job waited for ever at start-up."""
    with pytest.raises(ValueError, match=words):
        check_host(host)
    check_host("127.0.0.1")
