#!/usr/bin/env bash
# Re-renders the README's pictures (docs/images/) with the current code: the default scene at
# 1280x720, the example scenes at 640x360, and the fly-through strip (six frames, 3x2, stitched
# with Python's Pillow). Run from the repository root after `cargo build --release`.
set -euo pipefail
cloudscape=target/release/cloudscape
out=docs/images
"$cloudscape" render --out "$out/default.png"
for scene in above-the-layer inside-the-layer backlit-sunset cumulonimbus overcast-stratocumulus light-shafts; do
    "$cloudscape" render "scenes/$scene.toml" --width 640 --height 360 --out "$out/$scene.png"
done
frames=$(mktemp -d)
"$cloudscape" animate scenes/flythrough.toml --frames 6 --fps 0.55 --width 320 --height 180 \
    --set render.quality=medium --out "$frames"
python3 - "$frames" "$out/flythrough-strip.png" <<'PY'
import sys
from PIL import Image
frames = [Image.open(f"{sys.argv[1]}/frame_{i:04}.png") for i in range(6)]
w, h = frames[0].size
strip = Image.new("RGB", (3 * w, 2 * h))
for i, frame in enumerate(frames):
    strip.paste(frame, ((i % 3) * w, (i // 3) * h))
strip.save(sys.argv[2])
PY
rm -rf "$frames"
# The three techniques side by side: the default scene, the layer from above, inside the layer and
# the backlit sunset.
trio=$(mktemp -d)
for technique in raymarch particles sprites; do
    "$cloudscape" render --technique "$technique" --width 640 --height 360 --out "$trio/ground-$technique.png"
    for scene in above-the-layer inside-the-layer backlit-sunset; do
        "$cloudscape" render "scenes/$scene.toml" --technique "$technique" --width 640 --height 360 \
            --out "$trio/$scene-$technique.png"
    done
done
python3 - "$trio" "$out/techniques.png" <<'PY'
import sys
from PIL import Image
rows = ["ground", "above-the-layer", "inside-the-layer", "backlit-sunset"]
columns = ["raymarch", "particles", "sprites"]
images = [[Image.open(f"{sys.argv[1]}/{r}-{c}.png").convert("RGB") for c in columns] for r in rows]
w, h = images[0][0].size
grid = Image.new("RGB", (len(columns) * w, len(rows) * h))
for y, row in enumerate(images):
    for x, image in enumerate(row):
        grid.paste(image, (x * w, y * h))
grid.save(sys.argv[2])
PY
rm -rf "$trio"
# A day from dawn to dusk (scenes/time-of-day.toml at solar times 4.5, 9.5, 14.5 and 19.5 h: its
# path runs one solar hour per scene second from 4.3 h), and the four scenes built from METAR
# reports, each a row of four.
row=$(mktemp -d)
"$cloudscape" animate scenes/time-of-day.toml --frames 4 --start-s 0.2 --fps 0.2 \
    --width 480 --height 270 --out "$row/day"
for i in 0 1 2 3; do mv "$row/day/frame_000$i.png" "$row/day-$i.png"; done
for scene in metar-egll metar-low-stratus metar-fair-weather metar-thunderstorm; do
    "$cloudscape" render "scenes/$scene.toml" --width 480 --height 270 --out "$row/$scene.png"
done
python3 - "$row" "$out" <<'PY'
import sys
from PIL import Image
def strip(names, path):
    images = [Image.open(f"{sys.argv[1]}/{n}.png").convert("RGB") for n in names]
    w, h = images[0].size
    out = Image.new("RGB", (len(images) * w, h))
    for i, image in enumerate(images):
        out.paste(image, (i * w, 0))
    out.save(path)
strip(["day-0", "day-1", "day-2", "day-3"], f"{sys.argv[2]}/time-of-day-strip.png")
strip(["metar-egll", "metar-low-stratus", "metar-fair-weather", "metar-thunderstorm"],
      f"{sys.argv[2]}/metar-strip.png")
PY
rm -rf "$row"
