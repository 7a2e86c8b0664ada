#!/bin/sh
# `--display` end to end. Usage: cli_display.sh MODE OFV_BINARY WORK_DIR
#   no-display    without DISPLAY, `ofv simulate --display` and `ofv run --display` exit 2 with one
#                 line; a bad --display-speed exits 2
#   same-metrics  (under Xvfb) the episode's metrics and trajectory are those without --display
#   quit          (under Xvfb, xdotool) a left click pauses, another resumes, a right click ends the
#                 episode early: exit 0, files written, metrics.json marked ended_by_user
#   run-quit      (under Xvfb, xdotool) a left click pauses `ofv run`, q stops it as SIGTERM does
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
  # --display-speed: finite, in [0, 1000], only with --display.
  for speed in "--display --display-speed nan" "--display --display-speed -1" "--display-speed 2"; do
    # shellcheck disable=SC2086
    env -u DISPLAY "$ofv" simulate dvd-one-hand $speed --out "$work/nd" >/dev/null 2>&1
    rc=$?
    [ $rc -eq 2 ] || fail "ofv simulate $speed: exit $rc, not 2"
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
  # Everything but the compute times (wall clock) must be identical: metrics.json
  # without its two compute-time objects, trajectory.csv without its *_s columns.
  for d in plain display; do
    awk '/^  "(max|mean)_compute_time": \{/ {skip = 1} !skip {print} skip && /^  \}/ {skip = 0}' \
      "$work/$d/metrics.json" > "$work/$d.metrics"
    awk -F, 'NR == 1 {for (i = 1; i <= NF; i++) keep[i] = $i !~ /_s$/} {line = ""; for (i = 1; i <= NF; i++) if (keep[i]) line = line $i ","; print line}' \
      "$work/$d/trajectory.csv" > "$work/$d.trajectory"
  done
  grep -q '"mean_visible_fraction"' "$work/plain.metrics" || fail "metrics.json has no mean_visible_fraction"
  grep -q compute_time "$work/plain.metrics" && fail "the compute times were not removed"
  cmp "$work/plain.metrics" "$work/display.metrics" || { diff "$work/plain.metrics" "$work/display.metrics"; fail "metrics.json differ"; }
  cmp "$work/plain.trajectory" "$work/display.trajectory" || fail "trajectory.csv differ"
  [ "$(wc -l < "$work/plain.trajectory")" -ge 31 ] || fail "trajectory.csv is short"
  grep -q ended_by_user "$work/display/metrics.json" && fail "a full episode is marked ended_by_user"
  echo "same metrics and trajectory:"; grep -E '"(steps|mean_visible_fraction)"' "$work/plain.metrics"
  ;;
quit)
  xdotool=${OFV_XDOTOOL:-$(command -v xdotool)}
  case "$xdotool" in ""|*NOTFOUND) echo "xdotool not found: skipped"; exit 77 ;; esac
  rm -rf "$work/quit"
  "$ofv" simulate dvd-one-hand --set duration=20 --perception ground-truth --no-pictures --display \
    --out "$work/quit" >"$work/quit.out" 2>&1 &
  pid=$!
  win=$(timeout 20 "$xdotool" search --sync --onlyvisible --name "ofv simulate dvd-one-hand: scene" | head -1)
  [ -n "$win" ] || { kill $pid; fail "no scene window"; }
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
  # metrics.json (top-level members at two spaces): marked, shorter than
  # planned, and shorter than the wall-clock time less most of the 2 s pause.
  m="$work/quit/metrics.json"
  value() { sed -n "s/^  \"$1\": \(.*\),\{0,1\}$/\1/p" "$m" | sed 's/,$//'; }
  wall=$(( (ended - shown) / 1000000 ))
  echo "episode $(value duration_s) s of $(value planned_duration) in $wall ms of wall clock with a 2 s pause"
  [ "$(value ended_by_user)" = true ] || fail "metrics.json not marked ended_by_user"
  [ "$(value planned_duration)" = 20.0 ] || [ "$(value planned_duration)" = 20 ] || fail "planned_duration"
  awk -v d="$(value duration_s)" -v w="$wall" 'BEGIN {exit !(d > 0.2 && d * 1000 < w - 1500)}' ||
    fail "the pause did not hold the episode"
  [ "$(wc -l < "$work/quit/trajectory.csv")" -eq $(( $(value steps) + 1 )) ] || fail "trajectory.csv rows"
  ;;
run-quit)
  # `ofv run --display` on a recording: a left click pauses the run (the
  # robot is sent a zero velocity) and no command follows while it is
  # paused; the key q then stops it through the stop path of SIGTERM:
  # the last command line is the stop, exit 0.
  xdotool=${OFV_XDOTOOL:-$(command -v xdotool)}
  case "$xdotool" in ""|*NOTFOUND) echo "xdotool not found: skipped"; exit 77 ;; esac
  rec="$work/recording"
  [ -f "$rec/groundtruth.txt" ] || "$ofv" record dvd-one-hand --format tum --out "$rec" >/dev/null || fail "ofv record"
  frames=$(grep -vc '^#' "$rec/rgb.txt")
  "$ofv" run --robot camera --source "$rec" --dry-run --display >"$work/run.jsonl" 2>"$work/run.err" &
  pid=$!
  # The scene window opens before the first frame: the click waits in its queue.
  win=$(timeout 20 "$xdotool" search --sync --onlyvisible --name "ofv run: scene" | head -1)
  [ -n "$win" ] || { kill $pid; fail "no scene window"; }
  "$xdotool" mousemove --window "$win" 40 40 click 1   # pause
  sleep 0.5
  paused_at=$(wc -l < "$work/run.jsonl")
  sleep 2
  kill -0 $pid 2>/dev/null || fail "the run ended while paused"
  [ "$(wc -l < "$work/run.jsonl")" -eq "$paused_at" ] || fail "commands went on while paused"
  "$xdotool" mousemove --window "$win" 40 40 key q     # stop (q: the pointer's window has the focus)
  wait $pid
  rc=$?
  cat "$work/run.err"
  [ $rc -eq 0 ] || fail "exit $rc"
  grep -q "stopped from the display" "$work/run.err" || fail "not stopped from the display"
  tail -1 "$work/run.jsonl" | grep -q '"status": "stop"' || fail "the last line is not the stop"
  lines=$(wc -l < "$work/run.jsonl")
  echo "paused after $paused_at command lines; $lines (the stop included) of a $frames-frame recording"
  [ "$lines" -eq $((paused_at + 1)) ] || fail "commands after the pause other than the stop"
  [ "$lines" -lt "$frames" ] || fail "the run was not cut short"
  ;;
*) fail "unknown mode $mode" ;;
esac
