# Source me (bash): the venv, the colcon install space, and the DDS settings that keep ROS local.
_acti_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
source "$_acti_root/.venv/bin/activate"
export AMENT_PREFIX_PATH="$_acti_root/.venv" CMAKE_PREFIX_PATH="$_acti_root/.venv"
export ROS_AUTOMATIC_DISCOVERY_RANGE="${ROS_AUTOMATIC_DISCOVERY_RANGE:-LOCALHOST}"
export FASTDDS_BUILTIN_TRANSPORTS="${FASTDDS_BUILTIN_TRANSPORTS:-UDPv4}"
if [ -f "$_acti_root/install/setup.sh" ]; then
  COLCON_CURRENT_PREFIX="$_acti_root/install" source "$_acti_root/install/setup.sh"
fi
# no ROS 2 install sourced: the few `ros2` commands of the README (tools/ros2_lite.py)
command -v ros2 >/dev/null 2>&1 || export PATH="$_acti_root/tools/bin:$PATH"
unset _acti_root
