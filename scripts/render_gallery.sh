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
# The ray marcher beside the particle technique: the default scene and the layer from above.
pair=$(mktemp -d)
for technique in raymarch particles; do
    "$cloudscape" render --technique "$technique" --width 640 --height 360 --out "$pair/ground-$technique.png"
    "$cloudscape" render scenes/above-the-layer.toml --technique "$technique" --width 640 --height 360 \
        --out "$pair/above-$technique.png"
done
python3 - "$pair" "$out/raymarch-vs-particles.png" <<'PY'
import sys
from PIL import Image
names = ["ground-raymarch", "ground-particles", "above-raymarch", "above-particles"]
images = [Image.open(f"{sys.argv[1]}/{n}.png").convert("RGB") for n in names]
w, h = images[0].size
grid = Image.new("RGB", (2 * w, 2 * h))
for i, image in enumerate(images):
    grid.paste(image, ((i % 2) * w, (i // 2) * h))
grid.save(sys.argv[2])
PY
rm -rf "$pair"
