#!/usr/bin/env python3
"""Cross-check `cloudscape reference` against Mitsuba 3 on the same density grid.

Not part of `cargo test`. Needs Mitsuba 3 (`pip install mitsuba`, CPU variant scalar_rgb) and a
built `cloudscape` binary (`cargo build --release -p cloudscape-cli`).

1. Writes a scene that both renderers can represent exactly: the default cumulus layer under a
   constant sky, a point sun (Mitsuba's `directional` emitter has no disc), no ground, a single
   Henyey-Greenstein lobe (exact in Mitsuba), haze off.
2. `cloudscape export` samples its cloud field into `clouds.vol` and writes Mitsuba's `scene.xml`.
3. Mitsuba renders `scene.xml` (volpath, 1000 bounces) with scalar_rgb. The script sets volpath's
   `rr_depth` to `max_depth`: Mitsuba's default Russian roulette (from depth 5, survival at most
   0.95 per bounce) makes the estimates of albedo-1 clouds so heavy-tailed that 32-128 spp read
   about 8 % dark (a white furnace of this very scene reads 0.231 for a sky of 0.25).
4. `cloudscape reference` renders the same `.vol` grid placed in the same box (the layer itself
   removed), twice with different seeds: their disagreement is the Monte Carlo noise floor.
5. `cloudscape compare` scores both against Mitsuba; the script prints HDR-FLIP, relative MSE,
   luminance ratio, both renderers' samples per second and their ratio.

Usage: scripts/mitsuba_crosscheck.py [--spp N] [--width W] [--height H] [--resolution R]
       [--cloudscape PATH] [--work DIR]
"""

import argparse
import json
import re
import struct
import subprocess
import sys
import time
from pathlib import Path

SCENE = """# Written by scripts/mitsuba_crosscheck.py: what Mitsuba 3 can represent exactly.
[sun]
angular_radius_deg = 0.0

[sky]
model = "constant"
radiance = [0.25, 0.3, 0.4]
visibility_m = 10000000.0

[ground]
enabled = false

[phase]
model = "hg"
g = 0.85
"""


def run(command, capture=False):
    """Runs a command, echoing it; returns its stderr when asked."""
    print("$", " ".join(str(c) for c in command), flush=True)
    result = subprocess.run([str(c) for c in command], check=True, text=True,
                            capture_output=capture)
    return (result.stdout or "") + (result.stderr or "")


def vol_bbox(path):
    """The bounding box (min, max) in a Mitsuba .vol header (physics.md)."""
    header = path.read_bytes()[:48]
    if header[:3] != b"VOL":
        sys.exit(f"{path} is not a .vol file")
    values = struct.unpack("<6f", header[24:48])
    return values[:3], values[3:]


def extinction_scale(scene_xml):
    """The medium's extinction scale (the grid's peak) from the exported scene.xml."""
    match = re.search(r'<float name="scale" value="([^"]+)"', scene_xml.read_text())
    if not match:
        sys.exit(f"no extinction scale in {scene_xml}")
    return float(match.group(1))


def reference_scene(work, mitsuba_dir):
    """The scene with its layers replaced by the exported grid, in the grid's box."""
    lo, hi = vol_bbox(mitsuba_dir / "clouds.vol")
    centre = [(a + b) / 2 for a, b in zip(lo, hi)]
    size = [b - a for a, b in zip(lo, hi)]
    text = "layers = []\n" + SCENE + f"""
[[volumes]]
path = "{(mitsuba_dir / 'clouds.vol').resolve()}"
center_m = [{centre[0]}, {centre[1]}, {centre[2]}]
size_m = [{size[0]}, {size[1]}, {size[2]}]
extinction_per_m = {extinction_scale(mitsuba_dir / 'scene.xml')}
"""
    path = work / "reference.toml"
    path.write_text(text)
    return path


def without_early_roulette(scene_xml):
    """A copy of scene.xml whose volpath plays Russian roulette only from max_depth on."""
    text = scene_xml.read_text()
    integrator = '<integrator type="volpath">'
    if integrator not in text:
        sys.exit(f"no volpath integrator in {scene_xml}")
    patched = scene_xml.with_name("scene-no-early-roulette.xml")
    patched.write_text(text.replace(integrator, integrator + '<integer name="rr_depth" value="$max_depth"/>'))
    return patched


def render_mitsuba(scene_xml, out, spp, max_depth):
    """Renders with Mitsuba 3 scalar_rgb; returns samples per second (loading excluded)."""
    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    scene = mi.load_file(str(without_early_roulette(scene_xml)), spp=spp, max_depth=max_depth)
    start = time.perf_counter()
    image = mi.render(scene, spp=spp)
    seconds = time.perf_counter() - start
    mi.Bitmap(image).write(str(out))
    width, height = scene.sensors()[0].film().size()
    return width * height * spp / seconds


def render_ours(binary, scene, out, args, seed):
    """Runs `cloudscape reference`; returns samples per second as it reports them."""
    log = run([binary, "reference", scene, "--spp", args.spp, "--out", out, "--seed", seed,
               "--width", args.width, "--height", args.height], capture=True)
    match = re.search(r"([0-9.]+) samples/s", log)
    if not match:
        sys.exit(f"no samples/s in the output of cloudscape reference:\n{log}")
    return float(match.group(1))


def compare(binary, reference, test):
    """`cloudscape compare --json`: HDR-FLIP, relative MSE and luminance ratio of test."""
    out = subprocess.run([str(binary), "compare", str(reference), str(test), "--json"],
                         check=True, text=True, capture_output=True).stdout
    return json.loads(out)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--width", type=int, default=160)
    parser.add_argument("--height", type=int, default=90)
    parser.add_argument("--resolution", type=int, default=128, help="voxels along the grid's longest side")
    parser.add_argument("--size-km", type=float, default=16.0, help="side of the exported box")
    parser.add_argument("--max-depth", type=int, default=1000)
    parser.add_argument("--cloudscape", default="target/release/cloudscape")
    parser.add_argument("--work", default="target/mitsuba-crosscheck")
    args = parser.parse_args()
    work = Path(args.work)
    work.mkdir(parents=True, exist_ok=True)
    scene = work / "crosscheck.toml"
    scene.write_text(SCENE)
    mitsuba_dir = work / "mitsuba"
    run([args.cloudscape, "export", scene, "--out", mitsuba_dir, "--resolution", args.resolution,
         "--size-km", args.size_km, "--width", args.width, "--height", args.height])
    mitsuba_rate = render_mitsuba(mitsuba_dir / "scene.xml", work / "mitsuba.exr", args.spp, args.max_depth)
    ours = reference_scene(work, mitsuba_dir)
    ours_rate = render_ours(args.cloudscape, ours, work / "ours.exr", args, 1)
    render_ours(args.cloudscape, ours, work / "ours-seed2.exr", args, 2)
    against = compare(args.cloudscape, work / "mitsuba.exr", work / "ours.exr")
    floor = compare(args.cloudscape, work / "ours-seed2.exr", work / "ours.exr")
    print(f"\nMitsuba 3 vs cloudscape reference at {args.width}x{args.height}, {args.spp} spp:")
    print(f"  HDR-FLIP mean {against['flip_mean']:.4f} (p95 {against['flip_p95']:.4f}), "
          f"relMSE {against['relative_mse']:.5f}, luminance ratio {against['luminance_ratio']:.4f}")
    print(f"  noise floor (ours, two seeds): HDR-FLIP mean {floor['flip_mean']:.4f}, "
          f"relMSE {floor['relative_mse']:.5f}")
    print(f"  samples/s: cloudscape {ours_rate:.0f}, Mitsuba {mitsuba_rate:.0f}, "
          f"ratio {ours_rate / mitsuba_rate:.2f}")


if __name__ == "__main__":
    main()
