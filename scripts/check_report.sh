#!/usr/bin/env bash
# Checks a monomap HTML report (monomap report / demo / build --html) in
# headless Chromium. The page's own script records what it did as data
# attributes of <body> (src/monomap/report/web/report.js); this script
# loads the page, dumps the DOM and requires:
#   - the page finished (data-report-ready) with no JavaScript error, no
#     console.error and no "Uncaught" in the browser log;
#   - every embedded image decoded;
#   - at least MIN_CHARTS charts (default 1), none of them without data;
#   - the WebGL view rendered (SwiftShader, Chromium's software GL) with at
#     least MIN_VIEW_PERCENT (default 1) % of its pixels not background;
#   - no reference to an external resource.
#
# Usage: scripts/check_report.sh REPORT.html [SCREENSHOT.png]
#   SCREENSHOT.png  also save a screenshot of the page (1400 px wide;
#                   height from $SCREENSHOT_HEIGHT, default 4200).
# Environment: MIN_CHARTS, MIN_VIEW_PERCENT.
# Exit status: 0 ok, 1 check failed, 2 usage or setup error.
set -euo pipefail

if [[ $# -lt 1 || $# -gt 2 ]]; then
  echo "usage: $0 REPORT.html [SCREENSHOT.png]" >&2
  exit 2
fi
report=$1
screenshot=${2:-}
min_charts=${MIN_CHARTS:-1}
min_view_percent=${MIN_VIEW_PERCENT:-1}
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
  # A fresh profile per run; no network, no background services. WebGL
  # without a GPU: ANGLE on SwiftShader (--enable-unsafe-swiftshader is
  # needed since Chromium 137 for WebGL on the software fallback). The
  # virtual time budget lets the load event, the glTF parse and the first
  # render finish before the DOM is dumped.
  "$browser" --headless --no-sandbox --use-angle=swiftshader \
    --enable-unsafe-swiftshader --disable-quic \
    --no-first-run --disable-background-networking \
    --disable-component-update --disable-sync \
    --user-data-dir="$(mktemp -d -p "$work")" \
    --enable-logging=stderr --v=0 --virtual-time-budget=20000 "$@" \
    "file://$report_abs"
}

status=0
fail() { echo "check_report: FAIL: $*" >&2; status=1; }
if ! run_browser --window-size=1400,1000 --dump-dom >"$work/dom.html" \
    2>"$work/log.txt"; then
  echo "check_report: FAIL: chromium could not load the page" >&2
  tail -n 20 "$work/log.txt" >&2
  exit 1
fi

body=$(grep -o '<body[^>]*>' "$work/dom.html" | head -n 1 || true)
attr() { sed -n "s/.*data-$1=\"\\([0-9a-z]*\\)\".*/\\1/p" <<<"$body"; }
ready=$(attr report-ready)
js_errors=$(attr js-errors)
console_errors=$(attr console-errors)
images_total=$(attr images-total)
images_decoded=$(attr images-decoded)
charts=$(attr charts)
charts_empty=$(attr charts-empty)
webgl=$(attr webgl)
view_pixels=$(attr webgl-pixels)
view_drawn=$(attr webgl-non-background)

echo "check_report: $report: ready=${ready:-?} js_errors=${js_errors:-?}" \
  "console_errors=${console_errors:-?} images=${images_decoded:-?}/${images_total:-?}" \
  "charts=${charts:-?} (empty ${charts_empty:-?}) webgl=${webgl:-?}" \
  "view=${view_drawn:-?}/${view_pixels:-?} pixels not background"
if [[ $ready != 1 ]]; then
  fail "the page's script did not finish (data-report-ready missing)"
fi
if [[ ${js_errors:-1} -ne 0 || ${console_errors:-1} -ne 0 ]] ||
   grep -Eq 'Uncaught|CONSOLE.*[Ee]rror' "$work/log.txt"; then
  fail "JavaScript errors:"
  grep -E 'Uncaught|CONSOLE' "$work/log.txt" >&2 || true
fi
if [[ -z $images_total || ${images_decoded:-0} -ne $images_total ]]; then
  fail "${images_decoded:-?} of ${images_total:-?} images decoded"
fi
if [[ ${charts:-0} -lt $min_charts || ${charts_empty:-1} -ne 0 ]]; then
  fail "${charts:-0} charts (at least $min_charts wanted)," \
    "${charts_empty:-?} of them without data"
fi
if [[ $webgl != ready || -z $view_pixels ]]; then
  fail "the WebGL view did not render (webgl=${webgl:-?})"
elif (( view_drawn * 100 < view_pixels * min_view_percent )); then
  fail "the WebGL view is blank: $view_drawn of $view_pixels pixels drawn" \
    "(less than $min_view_percent %)"
fi
# External resources would break the self-contained promise.
if grep -Eq '(src|href)="(https?:)?//' "$report"; then
  fail "the page references external resources"
fi

if [[ -n $screenshot ]]; then
  height=${SCREENSHOT_HEIGHT:-4200}
  if run_browser --hide-scrollbars --window-size=1400,"$height" \
      --screenshot="$(realpath -m "$screenshot")" >/dev/null 2>&1 &&
     [[ -s $screenshot ]]; then
    echo "check_report: screenshot: $screenshot"
  else
    fail "no screenshot"
  fi
fi

[[ $status -eq 0 ]] && echo "check_report: OK"
exit $status
