#!/usr/bin/env python3
"""OpenVDB files for cloudscape's tests, written and read by OpenVDB itself (Debian: python3-openvdb).

    openvdb_files.py write DIR        writes the test files into DIR, each NAME.vdb with NAME.json:
                                      the grid to read, its active box, transform and sampled voxels
                                      ([i, j, k, value], as OpenVDB reads them back)
    openvdb_files.py write-sparse DIR writes sparse_1024.vdb (and .json): puffs over a 1024^3 box
    openvdb_files.py write-cumulus DIR writes cumulus.vdb, the README's figure's cloud
    openvdb_files.py write-corpus DIR writes the small files of the fuzz target's corpus
    openvdb_files.py check FILE GRID  reads GRID of FILE and prints, as JSON, its active box, voxel
                                      count, transform and every value at the voxels listed on stdin
                                      (a JSON list of [i, j, k])
"""
import json
import math
import os
import sys

import numpy as np
import pyopenvdb as vdb

RNG = np.random.default_rng(7)


def puff(n, scale=1.0):
    """A soft ball of density with a little noise, n^3 voxels, 0 outside its sphere."""
    axis = (np.arange(n) + 0.5) / n * 2.0 - 1.0
    x, y, z = np.meshgrid(axis, axis, axis, indexing="ij")
    r = np.sqrt(x * x + (1.3 * y) ** 2 + z * z)
    wobble = 0.08 * np.sin(7.0 * x) * np.cos(5.0 * z + 2.0 * y)
    return (np.clip(1.0 - r + wobble, 0.0, None) * scale).astype(np.float32)


def float_grid(name, transform):
    grid = vdb.FloatGrid()
    grid.name = name
    grid.gridClass = vdb.GridClass.FOG_VOLUME
    grid.transform = transform
    return grid


def samples(grid, regions, count):
    """`count` voxels inside the regions ([(ijk, array)]) and their values as OpenVDB reads them."""
    accessor = grid.getConstAccessor()
    out = []
    for _ in range(count):
        ijk, array = regions[RNG.integers(len(regions))]
        local = [int(RNG.integers(s)) for s in array.shape]
        voxel = [ijk[a] + local[a] for a in range(3)]
        out.append(voxel + [float(accessor.getValue(tuple(voxel)))])
    return out


def describe(grid, regions, count=2000):
    lo, hi = grid.evalActiveVoxelBoundingBox()
    xf = grid.transform
    origin = xf.indexToWorld((0, 0, 0))
    step = [xf.indexToWorld(tuple(1 if a == b else 0 for b in range(3)))[a] - origin[a] for a in range(3)]
    return {
        "grid": grid.name,
        "min": list(lo),
        "max": list(hi),
        "active_voxels": grid.activeVoxelCount(),
        "voxel_size": step,
        "translation": list(origin),
        "samples": samples(grid, regions, count) if regions else [],
    }


def save(directory, name, grids, grid_name, regions=None, count=2000):
    """Writes the grids as NAME.vdb and describes grid `grid_name` as OpenVDB reads it back."""
    path = os.path.join(directory, name + ".vdb")
    vdb.write(path, grids=grids)
    description = describe(vdb.read(path, grid_name), regions, count) if regions else {"grid": grid_name}
    with open(os.path.join(directory, name + ".json"), "w") as f:
        json.dump(description, f)


def write(directory):
    os.makedirs(directory, exist_ok=True)
    # A puff, Blosc-compressed (OpenVDB's default), 12.5 m voxels, off the origin.
    xf = vdb.createLinearTransform(voxelSize=12.5)
    xf.translate((-300.0, 1800.0, 250.0))
    grid = float_grid("density", xf)
    array = puff(24, 0.8)
    grid.copyFromArray(array, ijk=(-5, 3, 11), tolerance=0.0)
    save(directory, "puff", [grid], "density", [((-5, 3, 11), array)])

    # The same in half floats.
    half = grid.deepCopy()
    half.saveFloatAsHalf = True
    save(directory, "puff_half", [half], "density", [((-5, 3, 11), array)])

    # Three grids: a vector grid first, then two float grids; "density" is the second float.
    velocity = vdb.Vec3SGrid()
    velocity.name = "vel"
    velocity.fill((0, 0, 0), (7, 7, 7), (1.0, 0.0, 0.0), True)
    temperature = float_grid("temperature", vdb.createLinearTransform(voxelSize=1.0))
    temperature.fill((0, 0, 0), (9, 9, 9), 300.0, True)
    density = float_grid("density", vdb.createLinearTransform(voxelSize=4.0))
    array = puff(16, 2.0)
    density.copyFromArray(array, ijk=(8, 0, -8), tolerance=0.0)
    save(directory, "three_grids", [velocity, temperature, density], "density", [((8, 0, -8), array)])

    # Active tiles: a filled 128^3 node (an internal tile) and a filled 8^3 leaf-sized tile, then
    # pruned, beside voxels; per-axis voxel sizes from a scaling matrix.
    scaled = float_grid("density", vdb.createLinearTransform(
        [[2.0, 0, 0, 0], [0, 3.0, 0, 0], [0, 0, 4.0, 0], [10.0, 20.0, 30.0, 1.0]]))
    scaled.fill((0, 0, 0), (127, 127, 127), 0.25, True)
    scaled.fill((128, 0, 0), (135, 7, 7), 0.5, True)
    array = puff(12, 1.0)
    scaled.copyFromArray(array, ijk=(140, 3, 5), tolerance=0.0)
    scaled.prune()
    tiles = np.full((128, 128, 128), 0.25, np.float32)
    save(directory, "tiles", [scaled], "density", [((0, 0, 0), tiles), ((140, 3, 5), array)])

    # A level set, a rotated grid and a NaN voxel: each refused.
    sphere = vdb.createLevelSetSphere(radius=10.0, voxelSize=1.0)
    sphere.name = "surface"
    save(directory, "level_set", [sphere], "surface")
    c, s = math.cos(0.5), math.sin(0.5)
    rotated = float_grid("density", vdb.createLinearTransform(
        [[c, s, 0, 0], [-s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]))
    rotated.copyFromArray(puff(8), ijk=(0, 0, 0), tolerance=0.0)
    save(directory, "rotated", [rotated], "density")
    broken = float_grid("density", vdb.createLinearTransform(voxelSize=1.0))
    broken.copyFromArray(puff(8), ijk=(0, 0, 0), tolerance=0.0)
    broken.getAccessor().setValueOn((4, 4, 4), float("nan"))
    save(directory, "nan", [broken], "density")


def write_sparse(directory, size=1024, puffs=12, puff_voxels=96):
    """A sparse cloud over a size^3 box: `puffs` puffs of puff_voxels^3, corners included."""
    os.makedirs(directory, exist_ok=True)
    grid = float_grid("density", vdb.createLinearTransform(voxelSize=4.0))
    regions = []
    corners = [(0, 0, 0), (size - puff_voxels,) * 3]
    for p in range(puffs):
        ijk = corners[p] if p < len(corners) else tuple(int(v) for v in RNG.integers(0, size - puff_voxels, 3))
        if any(all(abs(ijk[a] - other[a]) < puff_voxels for a in range(3)) for other, _ in regions):
            continue
        array = puff(puff_voxels, 1.0)
        grid.copyFromArray(array, ijk=ijk, tolerance=0.0)
        regions.append((ijk, array))
    save(directory, "sparse_%d" % size, [grid], "density", regions, 500)


def write_corpus(directory):
    """Small files for the fuzz target's corpus (crates/cloudscape/tests/fuzz-regressions/vdb/)."""
    os.makedirs(directory, exist_ok=True)
    grid = float_grid("density", vdb.createLinearTransform(voxelSize=10.0))
    grid.copyFromArray(puff(6), ijk=(-3, 5, 2), tolerance=0.0)
    vdb.write(os.path.join(directory, "puff_blosc.vdb"), grids=[grid])
    half = grid.deepCopy()
    half.saveFloatAsHalf = True
    vdb.write(os.path.join(directory, "puff_half.vdb"), grids=[half])
    tiles = float_grid("density", vdb.createLinearTransform(voxelSize=1.0))
    tiles.fill((0, 0, 0), (127, 127, 127), 0.25, True)
    tiles.fill((128, 0, 0), (135, 7, 7), 0.5, True)
    tiles.prune()
    vel = vdb.Vec3SGrid()
    vel.name = "vel"
    vel.fill((0, 0, 0), (3, 3, 3), (1.0, 0.0, 0.0), True)
    vdb.write(os.path.join(directory, "tiles_and_vectors.vdb"), grids=[vel, tiles])
    sphere = vdb.createLevelSetSphere(radius=3.0, voxelSize=1.0, halfWidth=2.0)
    vdb.write(os.path.join(directory, "level_set.vdb"), grids=[sphere])


def write_cumulus(directory):
    """cumulus.vdb: a cumulus of overlapping blobs with eroded edges, 10 m voxels, its base at
    1500 m, as a cloud artist's tool would hand it over (the README's figure)."""
    os.makedirs(directory, exist_ok=True)
    shape = (192, 144, 160)
    x, y, z = np.meshgrid(*[np.arange(n, dtype=np.float32) for n in shape], indexing="ij")
    blobs = [((96, 40, 80), 42), ((60, 34, 70), 32), ((132, 36, 88), 34), ((80, 72, 84), 34),
             ((112, 70, 72), 30), ((96, 100, 80), 26), ((70, 30, 110), 24), ((124, 30, 50), 24)]
    field = np.zeros(shape, np.float32)
    for (cx, cy, cz), r in blobs:
        d = np.sqrt((x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2) / r
        field = np.maximum(field, 1.0 - d)
    # Billows: a few octaves of warped sines, eroding only (0 far from the blobs).
    billows = np.zeros(shape, np.float32)
    for octave, amplitude in enumerate([0.5, 0.3, 0.2]):
        f = 0.11 * 2.1 ** octave
        billows += amplitude * (np.sin(f * x + 1.7 * np.sin(0.7 * f * z + octave))
                                * np.sin(f * y + 1.3 * np.sin(0.6 * f * x))
                                * np.sin(f * z + 1.1 * np.sin(0.8 * f * y + 2.0 * octave)))
    flat_base = np.clip((y - 18.0) / 6.0, 0.0, 1.0)
    density = np.clip((field - 0.1 * (1.0 + billows)) * 3.0, 0.0, None) * flat_base
    grid = float_grid("density", vdb.createLinearTransform(voxelSize=10.0))
    grid.transform.translate((-960.0, 1320.0, -4800.0))
    grid.copyFromArray(density.astype(np.float32), ijk=(0, 0, 0), tolerance=0.0)
    vdb.write(os.path.join(directory, "cumulus.vdb"), grids=[grid])


def check(path, name):
    grid = vdb.read(path, name)
    voxels = json.load(sys.stdin)
    accessor = grid.getConstAccessor()
    description = describe(grid, [])
    description["values"] = [float(accessor.getValue(tuple(v))) for v in voxels]
    description["class"] = str(grid.gridClass)
    json.dump(description, sys.stdout)


if __name__ == "__main__":
    command = sys.argv[1]
    if command == "write":
        write(sys.argv[2])
    elif command == "write-sparse":
        write_sparse(sys.argv[2])
    elif command == "write-cumulus":
        write_cumulus(sys.argv[2])
    elif command == "write-corpus":
        write_corpus(sys.argv[2])
    elif command == "check":
        check(sys.argv[2], sys.argv[3])
    else:
        sys.exit(__doc__)
