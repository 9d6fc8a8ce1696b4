#!/bin/sh
# The node test (CTest ros.node): a real ROS master on the loopback interface on a free port,
# intervox_server, and the driver node_test, which publishes, checks and calls the services. The
# node's process id is written to <work>/server.pid (the driver lowers its memory limit for one
# message).
# Master and node are always stopped at the end (trap), and everything is bounded by timeouts.
#   run_node_test.sh <intervox_server> <node_test> <call_service> <work folder>
set -eu
server="$1" driver="$2" caller="$3" work="$4"
rm -rf "$work"
mkdir -p "$work"
export ROS_HOME="$work/ros_home" ROS_LOG_DIR="$work/log" ROS_IP=127.0.0.1
unset ROS_HOSTNAME ROS_NAMESPACE || true
port=$(python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
export ROS_MASTER_URI="http://127.0.0.1:$port"
master_pid="" server_pid=""
cleanup() {
  [ -n "$server_pid" ] && kill "$server_pid" 2>/dev/null || true
  [ -n "$master_pid" ] && kill "$master_pid" 2>/dev/null || true
  wait 2>/dev/null || true
}
trap cleanup EXIT INT TERM
echo "run_node_test: ROS_MASTER_URI=$ROS_MASTER_URI, logs in $work"
timeout 60 rosmaster --core -p "$port" >"$work/master.log" 2>&1 &
master_pid=$!
timeout 60 sh -c 'echo $$ >"$0"; exec "$@"' "$work/server.pid" \
  "$server" __name:=intervox_server _resolution:=0.1 _max_range:=5.0 _publish_rate:=0.0 \
  _update:=interval-mean _utility:=max-entropy _save_path:="$work/map" _stats_period:=1.0 \
  _planner/threads:=1 _explained:=true _color:=explained _insert_budget_mib:=64 >"$work/server.log" 2>&1 &
server_pid=$!
status=0
timeout 50 "$driver" "$caller" "$work" || status=$?
if ! kill -0 "$server_pid" 2>/dev/null; then
  echo "run_node_test: FAILED: intervox_server is no longer running"
  status=1
fi
echo "--- intervox_server log (last lines)"
tail -n 25 "$work/server.log"
exit $status
