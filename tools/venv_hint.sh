# Sourced by .venv/bin/activate (the Makefile adds the line): the venv alone lacks the interface
# packages built into install/ (acti_msgs, tf2_msgs) and the DDS settings, so say the way in.
if [ -z "${ACTI_ENV_SH:-}" ]; then
  echo "acti_ros2: this venv alone is not the environment (no acti_msgs, tf2_msgs): run" \
       "\`source $(dirname "$VIRTUAL_ENV")/tools/env.sh\` instead (it activates the venv too)" >&2
fi
