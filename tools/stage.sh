#!/usr/bin/env bash
# One stage of `make setup`: `tools/stage.sh NAME LOG COMMAND...` runs the command with all its
# output in LOG and says on the terminal, in one line, the stage's name and how long it took
# (or, if it failed, the log's last lines and where the rest is). The build's hundreds of lines
# stay in the log; what a person waits for is a line a stage.
name=$1 log=$2
shift 2
mkdir -p "$(dirname "$log")"
start=$SECONDS
"$@" >"$log" 2>&1
status=$?
took=$((SECONDS - start))
elapsed=$(printf '%d:%02d' $((took / 60)) $((took % 60)))
if [ $status -ne 0 ]; then
  printf '  %-58s FAILED after %s\n' "$name" "$elapsed" >&2
  tail -n 20 "$log" | sed 's/^/  | /' >&2
  printf '  the whole output: %s\n' "$log" >&2
  exit $status
fi
if grep -q "is up to date\|Nothing to be done" "$log" && [ $took -lt 2 ]; then
  printf '  %-58s up to date\n' "$name"
else
  printf '  %-58s %s\n' "$name" "$elapsed"
fi
