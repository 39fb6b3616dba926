#!/usr/bin/env bash
# Checks a monomap HTML report (monomap demo) in headless Chromium: the page
# loads, every <img> decodes (the page's inline script records the count of
# images with naturalWidth > 0 on <body>), and no JavaScript error occurs.
#
# Usage: scripts/check_report.sh REPORT.html [SCREENSHOT.png]
#   SCREENSHOT.png  also save a screenshot of the page (1400 px wide;
#                   height from $SCREENSHOT_HEIGHT, default 6000).
# Exit status: 0 ok, 1 check failed, 2 usage or setup error.
set -euo pipefail

if [[ $# -lt 1 || $# -gt 2 ]]; then
  echo "usage: $0 REPORT.html [SCREENSHOT.png]" >&2
  exit 2
fi
report=$1
screenshot=${2:-}
if [[ ! -f $report ]]; then
  echo "check_report: no such file: $report" >&2
  exit 2
fi
report_abs=$(realpath "$report")

browser=$(command -v chromium || command -v chromium-browser || true)
if [[ -z $browser ]]; then
  echo "check_report: installing chromium" >&2
  if ! apt-get install -y chromium >/dev/null 2>&1; then
    apt-get update >/dev/null && apt-get install -y chromium >/dev/null
  fi
  browser=$(command -v chromium || true)
  [[ -n $browser ]] || { echo "check_report: chromium missing" >&2; exit 2; }
fi

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
run_browser() {
  # A fresh profile per run; no network, no background services. The
  # virtual time budget lets the load event (and the inline script) finish
  # before the DOM is dumped.
  "$browser" --headless --no-sandbox --disable-gpu --disable-quic \
    --no-first-run --disable-background-networking \
    --disable-component-update --disable-sync \
    --user-data-dir="$(mktemp -d -p "$work")" \
    --enable-logging=stderr --v=0 --virtual-time-budget=15000 "$@" \
    "file://$report_abs"
}

status=0
if ! run_browser --dump-dom >"$work/dom.html" 2>"$work/log.txt"; then
  echo "check_report: FAIL: chromium could not load the page" >&2
  tail -n 20 "$work/log.txt" >&2
  exit 1
fi

body=$(grep -o '<body[^>]*>' "$work/dom.html" | head -n 1 || true)
attr() { sed -n "s/.*$1=\"\\([0-9]*\\)\".*/\\1/p" <<<"$body"; }
total=$(attr data-images-total)
decoded=$(attr data-images-decoded)
js_errors=$(attr data-js-errors)
in_source=$(grep -o '<img ' "$report" | wc -l)

echo "check_report: $report: $in_source <img> in the source, DOM reports" \
  "total=${total:-?} decoded=${decoded:-?} js_errors=${js_errors:-?}"
if [[ -z $total || -z $decoded ]]; then
  echo "check_report: FAIL: the page's check script did not run" >&2
  status=1
elif [[ $total -ne $in_source || $decoded -ne $total ]]; then
  echo "check_report: FAIL: $decoded of $total images decoded" \
    "($in_source in the source)" >&2
  status=1
fi
if [[ ${js_errors:-0} -ne 0 ]] ||
   grep -q 'Uncaught' "$work/log.txt"; then
  echo "check_report: FAIL: JavaScript errors:" >&2
  grep 'Uncaught' "$work/log.txt" >&2 || true
  status=1
fi
# External resources would break the self-contained promise.
if grep -Eq '(src|href)="(https?:)?//' "$report"; then
  echo "check_report: FAIL: the page references external resources" >&2
  status=1
fi

if [[ -n $screenshot ]]; then
  height=${SCREENSHOT_HEIGHT:-6000}
  if run_browser --hide-scrollbars --window-size=1400,"$height" \
      --screenshot="$(realpath -m "$screenshot")" >/dev/null 2>&1 &&
     [[ -s $screenshot ]]; then
    echo "check_report: screenshot: $screenshot"
  else
    echo "check_report: FAIL: no screenshot" >&2
    status=1
  fi
fi

[[ $status -eq 0 ]] && echo "check_report: OK"
exit $status
