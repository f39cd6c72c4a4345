#!/usr/bin/env python3
"""Cross-check `cloudscape reference` against Mitsuba 3 on exported canonical scenes.

Not part of `cargo test`. Needs Mitsuba 3 (`pip install mitsuba`, CPU variant scalar_rgb) and a
built `cloudscape` binary (`cargo build --release -p cloudscape-cli`). Method and results:
docs/mitsuba-crosscheck.md.

For each scene (by default three canonical scenes of the realism report: the default cumulus at a
65 deg sun, scenes/isolated-cumulus.toml and scenes/thin-stratus.toml; `--scenes` picks others):

1. `--set` overrides on top of the scene make it what Mitsuba 3 represents exactly: a constant
   sky, a point sun (Mitsuba's `directional` emitter has no disc), no ground, haze off, and the
   approximate-Mie phase function of Jendersie & d'Eon 2023 (`phase.model = "mie"`), which
   `cloudscape export` writes as a `tabphase` table that keeps its integral and mean cosine.
2. `cloudscape export` samples the scene's cloud field into `clouds.vol` and writes `scene.xml`.
3. Mitsuba renders `scene.xml` (volpath, 1000 bounces) with scalar_rgb. The script sets volpath's
   `rr_depth` to `max_depth`: Mitsuba's default Russian roulette (from depth 5, survival at most
   0.95 per bounce) makes the estimates of albedo-1 clouds so heavy-tailed that 32-128 spp read
   about 8 % dark (a white furnace of the default scene reads 0.231 for a sky of 0.25).
4. `cloudscape reference` renders the same `.vol` grid placed in the same box (the scene's layers
   removed by `--set layers=[]`, the grid added by `--set volumes=[...]`) at the same sample count,
   twice with different seeds: their disagreement is the Monte Carlo noise floor.
5. `cloudscape compare` scores ours against Mitsuba and against our second seed; the script prints
   HDR-FLIP, relative MSE, luminance ratio (ours / Mitsuba), both renderers' samples per second
   (rendering only, scene loading excluded) and their ratio, then a markdown table of all scenes.

Usage: scripts/mitsuba_crosscheck.py [--spp N] [--width W] [--height H] [--resolution R]
       [--size-km S] [--scenes NAME ...] [--cloudscape PATH] [--work DIR]
"""

import argparse
import json
import re
import struct
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

# Canonical scenes (crates/cloudscape-cli/src/report/canonical.rs): the scene file (None: the
# embedded default scene) and the overrides the report loads it with.
SCENES = {
    "cumulus-noon": (None, ["sun.elevation_deg=65"]),
    "backlit-sunset": ("scenes/backlit-sunset.toml", []),
    "overcast-below": ("scenes/overcast-stratocumulus.toml", []),
    "cumulonimbus": ("scenes/cumulonimbus.toml", []),
    "layer-above": ("scenes/above-the-layer.toml", []),
    "thin-stratus": ("scenes/thin-stratus.toml", []),
    "isolated-cumulus": ("scenes/isolated-cumulus.toml", []),
    "inside-layer": ("scenes/inside-the-layer.toml", []),
}
DEFAULT_SCENES = ["cumulus-noon", "isolated-cumulus", "thin-stratus"]

# What Mitsuba 3 represents exactly, on top of every scene.
EXACT = [
    "sun.angular_radius_deg=0.0",
    "sky.model=constant",
    "sky.radiance=[0.25, 0.3, 0.4]",
    "sky.visibility_m=10000000.0",
    "ground.enabled=false",
    "phase.model=mie",
]


def run(command, capture=False):
    """Runs a command, echoing it; returns its stdout and stderr when asked."""
    print("$", " ".join(str(c) for c in command), flush=True)
    result = subprocess.run([str(c) for c in command], check=True, text=True,
                            capture_output=capture)
    return (result.stdout or "") + (result.stderr or "")


def scene_arguments(name, extra=()):
    """The scene file (if any) and the `--set` arguments of a scene made exact for Mitsuba."""
    file, overrides = SCENES[name]
    args = [ROOT / file] if file else []
    for override in overrides + EXACT + list(extra):
        args += ["--set", override]
    return args


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


def grid_overrides(mitsuba_dir):
    """`--set` values replacing the scene's layers by the exported grid, in the grid's box."""
    lo, hi = vol_bbox(mitsuba_dir / "clouds.vol")
    centre = ", ".join(str((a + b) / 2) for a, b in zip(lo, hi))
    size = ", ".join(str(b - a) for a, b in zip(lo, hi))
    path = json.dumps(str((mitsuba_dir / "clouds.vol").resolve()))
    scale = extinction_scale(mitsuba_dir / "scene.xml")
    volume = f"{{path = {path}, center_m = [{centre}], size_m = [{size}], extinction_per_m = {scale}}}"
    return ["layers=[]", f"volumes=[{volume}]"]


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
    print(f"$ mitsuba scalar_rgb {scene_xml} spp={spp} max_depth={max_depth}", flush=True)
    scene = mi.load_file(str(without_early_roulette(scene_xml)), spp=spp, max_depth=max_depth)
    start = time.perf_counter()
    image = mi.render(scene, spp=spp)
    seconds = time.perf_counter() - start
    mi.Bitmap(image).write(str(out))
    width, height = scene.sensors()[0].film().size()
    return width * height * spp / seconds


def render_ours(binary, scene_args, out, args, seed):
    """Runs `cloudscape reference`; returns samples per second as it reports them."""
    log = run([binary, "reference", *scene_args, "--spp", args.spp, "--out", out, "--seed", seed,
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


def crosscheck(name, args):
    """Exports one scene, renders it with both renderers and scores them; returns the numbers."""
    work = Path(args.work) / name
    work.mkdir(parents=True, exist_ok=True)
    mitsuba_dir = work / "mitsuba"
    run([args.cloudscape, "export", *scene_arguments(name), "--out", mitsuba_dir,
         "--resolution", args.resolution, "--size-km", args.size_km,
         "--width", args.width, "--height", args.height])
    mitsuba_rate = render_mitsuba(mitsuba_dir / "scene.xml", work / "mitsuba.exr", args.spp,
                                  args.max_depth)
    ours = scene_arguments(name, grid_overrides(mitsuba_dir))
    ours_rate = render_ours(args.cloudscape, ours, work / "ours.exr", args, 1)
    render_ours(args.cloudscape, ours, work / "ours-seed2.exr", args, 2)
    result = {
        "scene": name,
        "against": compare(args.cloudscape, work / "mitsuba.exr", work / "ours.exr"),
        "floor": compare(args.cloudscape, work / "ours-seed2.exr", work / "ours.exr"),
        "mitsuba_rate": mitsuba_rate,
        "ours_rate": ours_rate,
    }
    print_result(result, args)
    return result


def print_result(r, args):
    """The numbers of one scene, as text."""
    against, floor = r["against"], r["floor"]
    print(f"\n{r['scene']}: Mitsuba 3 vs cloudscape reference at {args.width}x{args.height}, "
          f"{args.spp} spp:")
    print(f"  HDR-FLIP mean {against['flip_mean']:.4f} (p95 {against['flip_p95']:.4f}), "
          f"relMSE {against['relative_mse']:.5f}, luminance ratio {against['luminance_ratio']:.4f}")
    print(f"  noise floor (ours, two seeds): HDR-FLIP mean {floor['flip_mean']:.4f}, "
          f"relMSE {floor['relative_mse']:.5f}, luminance ratio {floor['luminance_ratio']:.4f}")
    print(f"  samples/s: cloudscape {r['ours_rate']:.0f}, Mitsuba {r['mitsuba_rate']:.0f}, "
          f"ratio {r['ours_rate'] / r['mitsuba_rate']:.2f}\n", flush=True)


def markdown_table(results):
    """All scenes as a markdown table."""
    lines = [
        "| Scene | HDR-FLIP vs Mitsuba (p95) | HDR-FLIP two seeds | relMSE vs Mitsuba "
        "| relMSE two seeds | Luminance ours / Mitsuba | Mitsuba samples/s | ours samples/s "
        "| ours / Mitsuba |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in results:
        a, f = r["against"], r["floor"]
        lines.append(
            f"| {r['scene']} | {a['flip_mean']:.4f} ({a['flip_p95']:.4f}) | {f['flip_mean']:.4f} "
            f"| {a['relative_mse']:.5f} | {f['relative_mse']:.5f} | {a['luminance_ratio']:.4f} "
            f"| {r['mitsuba_rate']:.0f} | {r['ours_rate']:.0f} "
            f"| {r['ours_rate'] / r['mitsuba_rate']:.2f} |")
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--width", type=int, default=160)
    parser.add_argument("--height", type=int, default=90)
    parser.add_argument("--resolution", type=int, default=128, help="voxels along the grid's longest side")
    parser.add_argument("--size-km", type=float, default=16.0, help="side of the exported box")
    parser.add_argument("--max-depth", type=int, default=1000)
    parser.add_argument("--scenes", nargs="+", default=DEFAULT_SCENES, choices=sorted(SCENES),
                        metavar="NAME", help=f"canonical scenes (default: {' '.join(DEFAULT_SCENES)})")
    parser.add_argument("--cloudscape", default="target/release/cloudscape")
    parser.add_argument("--work", default="target/mitsuba-crosscheck")
    args = parser.parse_args()
    results = [crosscheck(name, args) for name in args.scenes]
    print(f"Mitsuba 3 (scalar_rgb, volpath) vs cloudscape reference, {args.width}x{args.height}, "
          f"{args.spp} spp, grid {args.resolution} voxels over {args.size_km} km:\n")
    print(markdown_table(results))
    (Path(args.work) / "results.json").write_text(json.dumps(results, indent=2))


if __name__ == "__main__":
    main()
