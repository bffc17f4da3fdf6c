"""The build's choice of tf2_msgs (tools/own_tf2_msgs.py): ours only where none is installed."""
import importlib.util
import os

spec = importlib.util.spec_from_file_location(
    "own_tf2_msgs", os.path.join(os.path.dirname(__file__), "..", "tools", "own_tf2_msgs.py"))
own = importlib.util.module_from_spec(spec)
spec.loader.exec_module(own)


def test_ours_is_built_unless_another_prefix_has_tf2_msgs(tmp_path, monkeypatch):
    ours = os.path.join(own.ROOT, "install", "tf2_msgs")
    (tmp_path / own.MARKER).parent.mkdir(parents=True)
    (tmp_path / own.MARKER).write_text("")               # a ROS install's ament index entry
    monkeypatch.setenv("AMENT_PREFIX_PATH", os.pathsep.join([ours, "/nonexistent"]))
    assert own.installed_elsewhere() == []                # our own install does not count
    monkeypatch.setenv("AMENT_PREFIX_PATH", os.pathsep.join([ours, str(tmp_path)]))
    assert own.installed_elsewhere() == [str(tmp_path)]
