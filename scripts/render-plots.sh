#!/usr/bin/env bash
# Renders every picture trum draws into one folder, to be looked at before a release:
# each `trum plot` kind as PNG and SVG, the resonance and step-response plots, and the
# charts of a diagnosis report. SVGs (the plots' and the report's inline charts) are also
# rendered to PNG with rsvg-convert when it is installed (Debian: librsvg2-bin), so that
# what a browser shows can be checked as an image too; with Chromium installed (Debian:
# chromium) the HTML report and every SVG are also screenshotted by the headless browser.
#   scripts/render-plots.sh [OUT_DIR]        (default: out/pictures)
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
OUT="${1:-$ROOT/out/pictures}"
mkdir -p "$OUT"
cd "$ROOT"
cargo build -q --release -p trum-cli
T="$ROOT/target/release/trum"

for kind in speed-torque efficiency-torque power-torque speed-frequency efficiency-map speed-map temperature-map; do
  "$T" plot --motor trum60a --kind "$kind" -o "$OUT/$kind.png"
  "$T" plot --motor trum60a --kind "$kind" -o "$OUT/$kind.svg"
done
"$T" plot --motor trum60a --kind speed-torque --effect radial_friction=0.5 -o "$OUT/speed-torque-radial-friction.png"
"$T" resonance --plot "$OUT/resonance.png" -o /dev/null > /dev/null
"$T" resonance --plot "$OUT/resonance.svg" -o /dev/null > /dev/null
"$T" step --motor trum60a --duration-s 4e-3 --snapshot-at-s 2e-5,3.5e-3 \
  --plot "$OUT/step.png" --snapshot-plot "$OUT/friction.svg" -q > /dev/null 2>&1
"$T" synth --motor generic60 --effect radial_friction=1 --campaign preload-torque --noise 1 --seed 3 \
  -o "$OUT/bench.csv" 2> /dev/null
"$T" diagnose --motor generic60 --data "$OUT/bench.csv" --report "$OUT/report.html" -q > /dev/null

if command -v rsvg-convert > /dev/null; then
  for f in "$OUT"/*.svg; do rsvg-convert "$f" -o "${f%.svg}.svg.png"; done
  # the report's inline charts, one file each
  python3 - "$OUT" <<'EOF'
import re, sys, pathlib, subprocess
out = pathlib.Path(sys.argv[1])
html = (out / "report.html").read_text(encoding="utf-8")
for i, svg in enumerate(re.findall(r"<svg.*?</svg>", html, flags=re.S)):
    f = out / f"report-chart-{i:02d}.svg"
    f.write_text(svg, encoding="utf-8")
    subprocess.run(["rsvg-convert", str(f), "-o", str(f.with_suffix(".png"))], check=True)
EOF
else
  echo "rsvg-convert not found: SVGs are not rendered to PNG (apt-get install librsvg2-bin)"
fi
# the report and the SVG plots as a browser shows them: screenshots by headless Chromium
BROWSER=$(command -v chromium || command -v chromium-browser || command -v google-chrome || true)
if [ -n "$BROWSER" ]; then
  shot() { "$BROWSER" --headless --disable-gpu --no-sandbox --hide-scrollbars --window-size="$2" \
      --screenshot="$3" "file://$1" > /dev/null 2>&1; }
  shot "$OUT/report.html" 1200,4200 "$OUT/report.browser.png"
  for f in "$OUT"/*.svg; do shot "$f" 1100,800 "${f%.svg}.browser.png"; done
else
  echo "no Chromium found: the report and SVGs are not screenshotted in a browser (apt-get install chromium)"
fi
echo "pictures in $OUT"
