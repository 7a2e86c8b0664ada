#!/bin/sh
# `--display` end to end. Usage: cli_display.sh MODE OFV_BINARY WORK_DIR
#   no-display    without DISPLAY, `ofv simulate --display` and `ofv run --display` exit 2 with one line
#   same-metrics  (under Xvfb) the episode's metrics and trajectory are those without --display
#   quit          (under Xvfb, xdotool) a left click pauses, another resumes, a right click ends the
#                 episode early: exit 0, files written, metrics.json marked ended_by_user
set -u
mode=$1 ofv=$2 work=$3
mkdir -p "$work"
fail() { echo "FAIL: $*"; exit 1; }

case "$mode" in
no-display)
  for cmd in "simulate dvd-one-hand --set duration=0.2 --display --out $work/nd" \
             "run --robot viper850 --source sim:dvd-one-hand --display"; do
    # shellcheck disable=SC2086
    env -u DISPLAY "$ofv" $cmd >"$work/nd.out" 2>"$work/nd.err"
    rc=$?
    cat "$work/nd.err"
    [ $rc -eq 2 ] || fail "ofv $cmd: exit $rc, not 2"
    [ "$(wc -l < "$work/nd.err")" -eq 1 ] || fail "ofv $cmd: not one line on stderr"
    grep -q -- "--display: no display (DISPLAY is not set)" "$work/nd.err" || fail "ofv $cmd: message"
  done
  ;;
same-metrics)
  for d in plain display; do
    rm -rf "$work/$d"
    flag=""
    [ $d = display ] && flag=--display
    "$ofv" simulate dvd-one-hand --set duration=1 --perception ground-truth --no-pictures $flag --out "$work/$d" \
      >/dev/null || fail "ofv simulate $flag"
  done
  # Everything but the compute times (wall clock) must be identical.
  python3 - "$work/plain" "$work/display" <<'PY' || exit 1
import csv, json, sys
a, b = sys.argv[1], sys.argv[2]
def metrics(d):
    j = json.load(open(d + "/metrics.json"))
    for k in ("max_compute_time", "mean_compute_time"):
        j.pop(k)
    return j
def trajectory(d):
    rows = list(csv.reader(open(d + "/trajectory.csv")))
    keep = [i for i, h in enumerate(rows[0]) if not h.endswith("_s")]
    return [[r[i] for i in keep] for r in rows]
ma, mb = metrics(a), metrics(b)
if ma != mb:
    sys.exit("FAIL: metrics.json differ:\n%s\n%s" % (ma, mb))
ta, tb = trajectory(a), trajectory(b)
if ta != tb or len(ta) < 30:
    sys.exit("FAIL: trajectory.csv differ (%d and %d rows)" % (len(ta), len(tb)))
if "ended_by_user" in mb:
    sys.exit("FAIL: a full episode is marked ended_by_user")
print("same metrics and trajectory (%d steps, mean visible %.4f)" % (ma["steps"], ma["mean_visible_fraction"]))
PY
  ;;
quit)
  xdotool=${OFV_XDOTOOL:-$(command -v xdotool)}
  case "$xdotool" in ""|*NOTFOUND) echo "xdotool not found: skipped"; exit 77 ;; esac
  rm -rf "$work/quit"
  "$ofv" simulate dvd-one-hand --set duration=20 --perception ground-truth --no-pictures --display \
    --out "$work/quit" >"$work/quit.out" 2>&1 &
  pid=$!
  win=$(timeout 20 "$xdotool" search --sync --name "ofv simulate dvd-one-hand: camera" | head -1)
  [ -n "$win" ] || { kill $pid; fail "no camera window"; }
  shown=$(date +%s%N)
  sleep 1
  "$xdotool" mousemove --window "$win" 40 40 click 1   # pause
  sleep 2
  "$xdotool" mousemove --window "$win" 40 40 click 1   # resume
  sleep 1
  "$xdotool" mousemove --window "$win" 40 40 click 3   # end
  wait $pid
  rc=$?
  ended=$(date +%s%N)
  cat "$work/quit.out"
  [ $rc -eq 0 ] || fail "exit $rc"
  grep -q "ended by the user" "$work/quit.out" || fail "no 'ended by the user' line"
  python3 - "$work/quit" $(( (ended - shown) / 1000000 )) <<'PY' || exit 1
import json, sys
j = json.load(open(sys.argv[1] + "/metrics.json"))
wall = int(sys.argv[2]) / 1000.0
print("episode %.2f s of 20 in %.2f s of wall clock with a 2 s pause" % (j["duration_s"], wall))
if j.get("ended_by_user") is not True or j.get("planned_duration") != 20:
    sys.exit("FAIL: metrics.json not marked ended_by_user")
if not 0.2 < j["duration_s"] < wall - 1.5:
    sys.exit("FAIL: the pause did not hold the episode (%.2f s simulated in %.2f s)" % (j["duration_s"], wall))
if sum(1 for _ in open(sys.argv[1] + "/trajectory.csv")) != j["steps"] + 1:
    sys.exit("FAIL: trajectory.csv does not have the episode's steps")
PY
  ;;
*) fail "unknown mode $mode" ;;
esac
