#!/usr/bin/env bash
# The comparison's page in a real browser: writes `englobe compare scenes/sponza.toml --report
# target/report` (or REPORT_SCENE's), opens target/report/index.html in headless Chromium (Debian's `chromium`,
# installed when missing) and
#   - fails on any console message (a page with no script has none unless something failed to
#     load or parse),
#   - fails on an image that did not load: a copy of the page with a checking script added (the
#     page itself has none) is dumped after load, and every <img> must be complete with a natural
#     width, as many as the page holds,
#   - writes the screenshot (default target/report/screenshot.png).
#
# Needs root for apt-get when chromium is missing. Chromium runs with --no-sandbox, since CI runs
# as root, where its sandbox refuses to start.
# Usage: scripts/report-screenshot.sh [path/to/englobe] [screenshot.png] [compare options...]
#        (default: target/debug/englobe, built if needed). REPORT_SCENE=FILE compares another
#        scene (default scenes/sponza.toml, whose full comparison takes minutes: brute force over
#        its 66 453 triangles); CI checks the page of scenes/default.toml with
#        `--accel bvh-wide --width 160`, in seconds.
set -euo pipefail
cd "$(dirname "$0")/.."

START=$(date +%s)
if ! command -v chromium >/dev/null; then
    [ "$(id -u)" = 0 ] || { echo "report-screenshot: chromium is missing and installing it needs root" >&2; exit 1; }
    echo "report-screenshot: installing chromium"
    export DEBIAN_FRONTEND=noninteractive
    apt-get install -y -q --no-install-recommends chromium >/dev/null 2>&1 \
        || { apt-get update -q >/dev/null && apt-get install -y -q --no-install-recommends chromium >/dev/null; }
    echo "report-screenshot: chromium installed in $(( $(date +%s) - START )) s"
fi

ENGLOBE=${1:-target/debug/englobe}
SHOT=${2:-target/report/screenshot.png}
SCENE=${REPORT_SCENE:-scenes/sponza.toml}
shift $(( $# < 2 ? $# : 2 ))
[ -x "$ENGLOBE" ] || cargo build -q -p englobe-cli
"$ENGLOBE" compare "$SCENE" --report target/report -q "$@" >/dev/null
PAGE=$(realpath target/report/index.html)
mkdir -p "$(dirname "$SHOT")"
SHOT=$(realpath -m "$SHOT")

D=$(mktemp -d -t englobe-report.XXXXXX)
trap 'rm -rf "$D"' EXIT
# Each run gets its own profile, so that no earlier state (cache, crash reports) plays a part.
BROWSER=(chromium --headless --no-sandbox --disable-gpu --hide-scrollbars --no-first-run
         --user-data-dir="$D/profile" --enable-logging=stderr --v=0)

# The screenshot of the page as it is, and its console.
"${BROWSER[@]}" --window-size=1200,2600 --force-device-scale-factor=0.5 --screenshot="$SHOT" \
    "file://$PAGE" 2>"$D/console.log" >/dev/null || { cat "$D/console.log" >&2; exit 1; }
if grep -q "CONSOLE" "$D/console.log"; then
    echo "report-screenshot: the page wrote to the console:" >&2
    grep "CONSOLE" "$D/console.log" >&2
    exit 1
fi
[ -s "$SHOT" ] || { echo "report-screenshot: no screenshot written" >&2; exit 1; }

# Every image loaded: the same page with a script that counts, after load, the images that are
# complete and have a natural width, and writes the count into the page, which --dump-dom prints.
python3 - "$PAGE" "$D/checked.html" <<'EOF'
import sys
page = open(sys.argv[1], encoding="utf-8").read()
check = """<script>
window.addEventListener("load", () => {
  const images = Array.from(document.images);
  const loaded = images.filter((i) => i.complete && i.naturalWidth > 0).length;
  const out = document.createElement("div");
  out.id = "image-check";
  out.textContent = `images loaded: ${loaded} of ${images.length}`;
  document.body.appendChild(out);
});
</script>
"""
assert page.count("</body>") == 1, "one </body>"
open(sys.argv[2], "w", encoding="utf-8").write(page.replace("</body>", check + "</body>"))
EOF
"${BROWSER[@]}" --virtual-time-budget=10000 --dump-dom "file://$D/checked.html" 2>"$D/dom.log" >"$D/dom.html" \
    || { cat "$D/dom.log" >&2; exit 1; }
if grep -q "CONSOLE" "$D/dom.log"; then
    echo "report-screenshot: the page wrote to the console:" >&2
    grep "CONSOLE" "$D/dom.log" >&2
    exit 1
fi
EXPECTED=$(grep -o "<img " "$PAGE" | wc -l)
RESULT=$(grep -o "images loaded: [0-9]* of [0-9]*" "$D/dom.html" || true)
if [ "$EXPECTED" -eq 0 ] || [ "$RESULT" != "images loaded: $EXPECTED of $EXPECTED" ]; then
    echo "report-screenshot: expected all $EXPECTED images of the page to load; the browser says: ${RESULT:-nothing}" >&2
    exit 1
fi
echo "report-screenshot: $RESULT, no console message; wrote $SHOT in $(( $(date +%s) - START )) s"
