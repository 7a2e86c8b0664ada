#!/bin/sh
# Runs a command under a fresh Xvfb (xvfb-run -a, 24-bit 1600x1200), or exits
# 77 (ctest: skipped) where xvfb-run is not installed. -noreset: otherwise the
# server resets each time its last client leaves, and refuses the next
# connection for a moment (a test opening a second display failed so).
xvfb_run=${OFV_XVFB_RUN:-$(command -v xvfb-run)}
case "$xvfb_run" in
  ""|*NOTFOUND) echo "xvfb-run not found: skipped (apt-get install xvfb)"; exit 77 ;;
esac
exec "$xvfb_run" -a -s "-screen 0 1600x1200x24 -noreset" "$@"
