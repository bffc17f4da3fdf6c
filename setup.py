"""ament_python package acti_ros2: the nodes and their ROS-free cores."""
from glob import glob

from setuptools import Extension, find_packages, setup

PACKAGE = "acti_ros2"

setup(
    name=PACKAGE,
    version="0.1.0",
    packages=find_packages(include=["acti_middle_node*", "vehicle_node*", "acti_bringup*",
                                    "acti_motion*", "acti_sim*", "acti_view*", "strolic*",
                                    "roboline*", "acti_record*"]),
    package_data={"roboline": ["grammar.lark"]},
    # built in place by colcon's `setup.py develop` (make setup): acti_bringup.serving.unlocked
    ext_modules=[Extension("acti_bringup.serving._respond", ["acti_bringup/serving/_respond.c"])],
    data_files=[
        ("share/ament_index/resource_index/packages", [f"resource/{PACKAGE}"]),
        (f"share/{PACKAGE}", ["package.xml"]),
        (f"share/{PACKAGE}/urdf", glob("urdf/*.urdf")),
        (f"share/{PACKAGE}/config", glob("config/*.yaml")),
        (f"share/{PACKAGE}/config/worlds", glob("config/worlds/*.yaml")),
        (f"share/{PACKAGE}/config/nav2", glob("config/nav2/*.yaml")),
    ],
    install_requires=["setuptools"],
    tests_require=["pytest"],
    extras_require={"test": ["pytest"]},
    zip_safe=False,
    maintainer="acti_ros2 developers",
    maintainer_email="dev@acti-ros2.example.org",
    description="ACT manipulator ports, VehicleService and STROLIC on ROS 2 Jazzy",
    license="Apache-2.0",
    entry_points={
        "console_scripts": [
            "acti_middle_node = acti_middle_node.__main__:main",
            "vehicle_node = vehicle_node.__main__:main",
            "acti_robot = acti_bringup.__main__:main",
        ],
    },
)
