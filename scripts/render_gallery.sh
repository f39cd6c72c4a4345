#!/usr/bin/env bash
# Re-renders the README's pictures (docs/images/) with the current code: the default scene at
# 1280x720, the example scenes at 640x360, and the fly-through strip (six frames, 3x2, stitched
# with Python's Pillow). Run from the repository root after `cargo build --release`.
set -euo pipefail
cloudscape=target/release/cloudscape
out=docs/images
"$cloudscape" render --out "$out/default.png"
for scene in above-the-layer inside-the-layer backlit-sunset cumulonimbus overcast-stratocumulus; do
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
# The three techniques side by side: the default scene, the layer from above, inside the layer.
trio=$(mktemp -d)
for technique in raymarch particles sprites; do
    "$cloudscape" render --technique "$technique" --width 640 --height 360 --out "$trio/ground-$technique.png"
    "$cloudscape" render scenes/above-the-layer.toml --technique "$technique" --width 640 --height 360 \
        --out "$trio/above-$technique.png"
    "$cloudscape" render scenes/inside-the-layer.toml --technique "$technique" --width 640 --height 360 \
        --out "$trio/inside-$technique.png"
done
python3 - "$trio" "$out/techniques.png" <<'PY'
import sys
from PIL import Image
rows, columns = ["ground", "above", "inside"], ["raymarch", "particles", "sprites"]
images = [[Image.open(f"{sys.argv[1]}/{r}-{c}.png").convert("RGB") for c in columns] for r in rows]
w, h = images[0][0].size
grid = Image.new("RGB", (len(columns) * w, len(rows) * h))
for y, row in enumerate(images):
    for x, image in enumerate(row):
        grid.paste(image, (x * w, y * h))
grid.save(sys.argv[2])
PY
rm -rf "$trio"
