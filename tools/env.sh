# Source me (bash): the venv, the colcon install space, and the DDS settings that keep ROS local.
_acti_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
ACTI_ENV_SH=1 source "$_acti_root/.venv/bin/activate"   # (quiet: this is the way in)
# put $2 first on the path variable $1, once (sourcing twice adds nothing)
_acti_prepend() {
  case ":${!1}:" in *":$2:"*) ;; *) export "$1=$2${!1:+:${!1}}" ;; esac
}
# the venv's ROS packages first; an installed ROS 2 (sourced before) stays behind them
_acti_prepend AMENT_PREFIX_PATH "$_acti_root/.venv"
_acti_prepend CMAKE_PREFIX_PATH "$_acti_root/.venv"
export ROS_AUTOMATIC_DISCOVERY_RANGE="${ROS_AUTOMATIC_DISCOVERY_RANGE:-LOCALHOST}"
export FASTDDS_BUILTIN_TRANSPORTS="${FASTDDS_BUILTIN_TRANSPORTS:-UDPv4}"
if [ -f "$_acti_root/install/setup.sh" ]; then
  COLCON_CURRENT_PREFIX="$_acti_root/install" source "$_acti_root/install/setup.sh"
fi
# the console scripts: acti_robot (both nodes and the view), acti_middle_node, vehicle_node
_acti_prepend PATH "$_acti_root/install/acti_ros2/lib/acti_ros2"
# no ROS 2 install sourced: the `ros2` commands a user needs (tools/ros2_lite.py)
command -v ros2 >/dev/null 2>&1 || _acti_prepend PATH "$_acti_root/tools/bin"
unset _acti_root
unset -f _acti_prepend
