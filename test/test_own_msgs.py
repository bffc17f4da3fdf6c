"""The build's choice of our standard interface packages (tools/own_msgs.py): ours only where
none is installed."""
import importlib.util
import os

import pytest

spec = importlib.util.spec_from_file_location(
    "own_msgs", os.path.join(os.path.dirname(__file__), "..", "tools", "own_msgs.py"))
own = importlib.util.module_from_spec(spec)
spec.loader.exec_module(own)


@pytest.mark.parametrize("package", own.OWN_PACKAGES)
def test_ours_is_built_unless_another_prefix_has_it(package, tmp_path, monkeypatch):
    ours = os.path.join(own.ROOT, "install", package)
    (tmp_path / own.marker(package)).parent.mkdir(parents=True)
    (tmp_path / own.marker(package)).write_text("")     # a ROS install's ament index entry
    monkeypatch.setenv("AMENT_PREFIX_PATH", os.pathsep.join([ours, "/nonexistent"]))
    assert own.installed_elsewhere(package) == []       # our own install does not count
    assert os.path.join("msg_defs", package) in own.own_base_paths()
    monkeypatch.setenv("AMENT_PREFIX_PATH", os.pathsep.join([ours, str(tmp_path)]))
    assert own.installed_elsewhere(package) == [str(tmp_path)]


def test_every_own_package_is_in_msg_defs():
    for package in own.OWN_PACKAGES:
        assert os.path.isfile(os.path.join(own.ROOT, "msg_defs", package, "package.xml"))
