//! OpenVDB files in and out, held to OpenVDB itself: files written by OpenVDB's Python module
//! (`crates/cloudscape/tests/vdb/openvdb_files.py`, Debian's python3-openvdb) read with the values
//! OpenVDB reads back from them; files cloudscape writes read by OpenVDB with the values written;
//! bad files refused with located errors; a sparse 1024^3 cloud loaded in the memory of its
//! bricks, and rendered.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use cloudscape::field::BrickGrid;
use cloudscape::field::sparse::{Block, SparseVoxels, block_local};
use cloudscape::field::vdb::{VdbError, VdbGrid, VdbTransform, read_vdb, write_vdb};
use cloudscape::field::voxel::ValuePolicy;
use cloudscape::image::LdrImage;
use glam::{DVec3, IVec3};
use serde::Deserialize;

use crate::needs::{self, Missing};
use crate::puffs::add_ball;
use crate::support::{Scratch, TINY, cloudscape};

/// What the script says of a grid: as OpenVDB reads it.
#[derive(Deserialize)]
struct Description {
    grid: String,
    #[serde(default)]
    min: [i32; 3],
    #[serde(default)]
    max: [i32; 3],
    #[serde(default)]
    active_voxels: u64,
    #[serde(default)]
    voxel_size: [f64; 3],
    #[serde(default)]
    translation: [f64; 3],
    /// Voxels and their values: `[i, j, k, value]`.
    #[serde(default)]
    samples: Vec<[f64; 4]>,
    /// Values at the voxels given to `check`.
    #[serde(default)]
    values: Vec<f64>,
    /// The grid's class (`check`).
    #[serde(default)]
    class: String,
}

/// The script that makes and reads OpenVDB files with OpenVDB.
fn script() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../cloudscape/tests/vdb/openvdb_files.py")
}

/// A Python that imports OpenVDB's module: Debian's (`/usr/bin/python3`) before one on `PATH`.
fn openvdb_python() -> Option<&'static str> {
    ["/usr/bin/python3", "python3"].into_iter().find(|python| {
        Command::new(python)
            .args(["-c", "import pyopenvdb"])
            .stderr(Stdio::null())
            .status()
            .is_ok_and(|s| s.success())
    })
}

/// The Python with OpenVDB, or None when the test cannot run (see [`needs::met`]).
fn python_or_skip() -> Option<&'static str> {
    let python = openvdb_python();
    let missing = python.is_none().then(|| Missing {
        what: "OpenVDB's Python module (pyopenvdb)".into(),
        remedy: "Debian: apt-get install python3-openvdb".into(),
    });
    needs::met(missing).then(|| python.expect("found"))
}

/// Runs the script with `args`, `stdin` on its input; its output.
fn run_script(python: &str, args: &[&str], stdin: &str) -> String {
    let mut child = Command::new(python)
        .arg(script())
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start python");
    child
        .stdin
        .take()
        .expect("stdin")
        .write_all(stdin.as_bytes())
        .expect("write stdin");
    let output = child.wait_with_output().expect("python ran");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{args:?}: {stderr}");
    String::from_utf8(output.stdout).expect("UTF-8")
}

/// The description OpenVDB wrote beside `name.vdb`.
fn description(dir: &Path, name: &str) -> Description {
    let text = std::fs::read_to_string(dir.join(format!("{name}.json"))).expect("description");
    serde_json::from_str(&text).expect("JSON")
}

/// Reads grid `description.grid` of `dir/name.vdb` and checks it against what OpenVDB read.
fn assert_read_as_openvdb_reads(dir: &Path, name: &str) -> VdbGrid {
    let expected = description(dir, name);
    let path = dir.join(format!("{name}.vdb"));
    let grid = read_vdb(&path, Some(&expected.grid), ValuePolicy::Reject)
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    assert_eq!(
        grid.voxels.min.to_array(),
        expected.min,
        "{name}: active box"
    );
    assert_eq!(
        grid.voxels.max.to_array(),
        expected.max,
        "{name}: active box"
    );
    let close = |a: DVec3, b: [f64; 3]| (a - DVec3::from(b)).abs().max_element() < 1e-9;
    assert!(
        close(grid.transform.voxel_size, expected.voxel_size),
        "{name}: voxel size"
    );
    assert!(
        close(grid.transform.translation, expected.translation),
        "{name}: offset"
    );
    assert!(expected.samples.len() >= 500, "{name}: too few samples");
    for [i, j, k, value] in &expected.samples {
        let voxel = IVec3::new(*i as i32, *j as i32, *k as i32);
        assert_eq!(
            grid.voxels.value(voxel),
            *value as f32,
            "{name}: voxel {voxel}"
        );
    }
    grid
}

#[test]
fn files_written_by_openvdb_read_with_the_values_openvdb_reads() {
    let Some(python) = python_or_skip() else {
        return;
    };
    let scratch = Scratch::new("vdb-read");
    run_script(
        python,
        &["write", &scratch.path().display().to_string()],
        "",
    );
    // Blosc-compressed with active-mask compression (OpenVDB's default), half floats, a file of
    // three grids (the float grid asked for by name), active tiles of 128^3 and 8^3 voxels
    // and per-axis voxel sizes.
    for name in ["puff", "puff_half", "three_grids", "tiles"] {
        let grid = assert_read_as_openvdb_reads(scratch.path(), name);
        let bricks = BrickGrid::from_sparse(&grid.voxels).expect("bricks");
        assert!(bricks.max_value() > 0.0, "{name}: no density");
    }
    let tiles = read_vdb(&scratch.join("tiles.vdb"), None, ValuePolicy::Reject).unwrap();
    assert_eq!(
        description(scratch.path(), "tiles").active_voxels,
        128 * 128 * 128 + 8 * 8 * 8 + active_voxel_count(&tiles, IVec3::new(140, 0, 0)),
        "the 128^3 and 8^3 tiles and the puff's voxels"
    );
}

/// Voxels with a value other than 0 in the blocks from `from` on (along x).
fn active_voxel_count(grid: &VdbGrid, from: IVec3) -> u64 {
    let mut count = 0;
    for (origin, block) in &grid.voxels.blocks {
        for local in (0..512).map(block_local) {
            let v = *origin + local.as_ivec3();
            count += u64::from(v.x >= from.x && block.value(local) != 0.0);
        }
    }
    count
}

#[test]
fn bad_files_are_refused_with_located_errors() {
    let Some(python) = python_or_skip() else {
        return;
    };
    let scratch = Scratch::new("vdb-bad");
    let dir = scratch.path();
    run_script(python, &["write", &dir.display().to_string()], "");
    let refused = |name: &str, grid: Option<&str>| {
        let path = dir.join(format!("{name}.vdb"));
        read_vdb(&path, grid, ValuePolicy::Reject)
            .expect_err(name)
            .to_string()
    };
    assert!(refused("level_set", None).contains("level set"));
    assert!(refused("rotated", None).contains("rotates or shears"));
    let nan = refused("nan", None);
    assert!(nan.contains("NaN at voxel [4, 4, 4]"), "{nan}");
    let replaced = read_vdb(&dir.join("nan.vdb"), None, ValuePolicy::Replace).expect("sanitized");
    assert_eq!(replaced.voxels.value(IVec3::splat(4)), 0.0);
    assert!(refused("three_grids", Some("vel")).contains("Tree_vec3s_5_4_3"));
    let missing = refused("three_grids", Some("smoke"));
    assert!(
        missing.contains(r#"no grid is named "smoke"; the file holds "vel""#),
        "{missing}"
    );
    // Every truncation is an error, never a panic.
    let bytes = std::fs::read(dir.join("puff.vdb")).unwrap();
    for length in (0..bytes.len()).step_by(97) {
        let cut = dir.join("cut.vdb");
        std::fs::write(&cut, &bytes[..length]).unwrap();
        let error = read_vdb(&cut, None, ValuePolicy::Reject).expect_err("truncated");
        assert!(
            matches!(error, VdbError::NotVdb { .. } | VdbError::Malformed { .. }),
            "{length} bytes: {error}"
        );
    }
    // Through a scene: the error names the file, the grid and the scene key; nothing is written.
    let scene = "layers = []\n[[volumes]]\npath = \"nan.vdb\"\n";
    std::fs::write(dir.join("nan.toml"), scene).unwrap();
    let run = cloudscape(dir, &["render", "nan.toml", "--out", "nan.png"], true);
    assert!(!run.success);
    assert!(
        run.stderr.contains("nan.toml:3:8: volumes.0.path: "),
        "{}",
        run.stderr
    );
    assert!(
        run.stderr.contains("value NaN at voxel [4, 4, 4]"),
        "{}",
        run.stderr
    );
    let scene = "layers = []\n[[volumes]]\npath = \"three_grids.vdb\"\ngrid = \"smoke\"\n";
    std::fs::write(dir.join("smoke.toml"), scene).unwrap();
    let run = cloudscape(dir, &["render", "smoke.toml", "--out", "smoke.png"], true);
    assert!(run.stderr.contains("volumes.0.grid: "), "{}", run.stderr);
    assert!(!dir.join("nan.png").exists() && !dir.join("smoke.png").exists());
}

/// A cloud of two puffs 200 voxels apart, one block a uniform tile, off the block lattice.
fn two_puffs() -> VdbGrid {
    let mut voxels = SparseVoxels::default();
    add_ball(&mut voxels, IVec3::new(-6, 20, 22), 10.0, 0.7);
    add_ball(&mut voxels, IVec3::new(200, 33, 9), 7.0, 0.7);
    voxels
        .blocks
        .insert(IVec3::new(96, 0, 0), Block::Uniform(0.25));
    VdbGrid {
        name: "cloud".into(),
        transform: VdbTransform {
            voxel_size: DVec3::new(5.0, 4.0, 6.0),
            translation: DVec3::new(-100.0, 2000.0, 300.0),
        },
        voxels,
    }
}

/// The voxels of `grid`'s blocks and their values.
fn voxels_and_values(grid: &VdbGrid) -> (Vec<[i32; 3]>, Vec<f32>) {
    let mut origins: Vec<IVec3> = grid.voxels.blocks.keys().copied().collect();
    origins.sort_by_key(|o| o.to_array());
    let voxels: Vec<[i32; 3]> = origins
        .iter()
        .flat_map(|o| {
            (0..512)
                .step_by(3)
                .map(move |i| *o + block_local(i).as_ivec3())
        })
        .map(|v| v.to_array())
        .collect();
    let values = voxels
        .iter()
        .map(|v| grid.voxels.value(IVec3::from(*v)))
        .collect();
    (voxels, values)
}

/// What OpenVDB reads from `path`'s grid `name` at `voxels`.
fn openvdb_reads(python: &str, path: &Path, name: &str, voxels: &[[i32; 3]]) -> Description {
    let path = path.display().to_string();
    let input = serde_json::to_string(voxels).unwrap();
    serde_json::from_str(&run_script(python, &["check", &path, name], &input)).expect("JSON")
}

#[test]
fn files_cloudscape_writes_read_in_openvdb_with_the_same_values() {
    let Some(python) = python_or_skip() else {
        return;
    };
    let scratch = Scratch::new("vdb-write");
    let grid = two_puffs();
    let path = scratch.join("cloud.vdb");
    write_vdb(&path, &grid).expect("written");
    let (voxels, values) = voxels_and_values(&grid);
    let read = openvdb_reads(python, &path, "cloud", &voxels);
    assert_eq!(read.grid, "cloud");
    assert_eq!(read.class, "fog volume");
    assert_eq!(read.voxel_size, [5.0, 4.0, 6.0]);
    assert_eq!(read.translation, [-100.0, 2000.0, 300.0]);
    let read_values: Vec<f32> = read.values.iter().map(|v| *v as f32).collect();
    assert_eq!(read_values, values, "OpenVDB reads other values");
    let nonzero = values.iter().filter(|v| **v != 0.0).count() as u64;
    assert!(read.active_voxels >= nonzero && nonzero > 1000);
    // And cloudscape reads its own file back unchanged.
    let back = read_vdb(&path, None, ValuePolicy::Reject).expect("read back");
    let back_values: Vec<f32> = voxels
        .iter()
        .map(|v| back.voxels.value(IVec3::from(*v)))
        .collect();
    assert_eq!(back_values, values);
    assert_eq!(back.voxels.min.to_array(), read.min);
    assert_eq!(back.voxels.max.to_array(), read.max);
}

#[test]
fn export_vdb_round_trips_through_openvdb_and_renders() {
    let Some(python) = python_or_skip() else {
        return;
    };
    let scratch = Scratch::new("vdb-export");
    let args = [
        "export",
        "--resolution",
        "24",
        "--size-km",
        "6",
        "--vdb",
        "clouds.vdb",
    ];
    let run = cloudscape(scratch.path(), &args, false);
    assert!(run.success, "{}", run.stderr);
    assert!(
        run.stderr.contains("[[volumes]]\npath = \"clouds.vdb\""),
        "{}",
        run.stderr
    );
    let ours = read_vdb(
        &scratch.join("clouds.vdb"),
        Some("density"),
        ValuePolicy::Reject,
    )
    .expect("read the export");
    let (voxels, values) = voxels_and_values(&ours);
    let peak = ours
        .voxels
        .blocks
        .values()
        .map(Block::max_value)
        .fold(0.0, f32::max);
    assert_eq!(peak, 1.0, "the peak is not 1");
    let read = openvdb_reads(python, &scratch.join("clouds.vdb"), "density", &voxels);
    let read_values: Vec<f32> = read.values.iter().map(|v| *v as f32).collect();
    assert_eq!(read_values, values, "OpenVDB reads other values");
    // The printed entry draws it where the layer was.
    let extinction = run
        .stderr
        .split("extinction_per_m = ")
        .nth(1)
        .expect("entry");
    let scene = format!(
        "layers = []\n[[volumes]]\npath = \"clouds.vdb\"\nextinction_per_m = {}\n",
        extinction.lines().next().unwrap()
    );
    std::fs::write(scratch.join("vdb.toml"), scene).unwrap();
    let mut args = vec!["render", "vdb.toml", "--out", "vdb.png"];
    args.extend(TINY);
    let run = cloudscape(scratch.path(), &args, true);
    assert!(run.success, "{}", run.stderr);
    let sky = LdrImage::read_png(&scratch.join("vdb.png")).expect("rendered");
    let mut args = vec![
        "render",
        "--out",
        "layer.png",
        "--set",
        "layers.0.coverage=0",
    ];
    args.extend(TINY);
    assert!(cloudscape(scratch.path(), &args, true).success);
    let clear = LdrImage::read_png(&scratch.join("layer.png")).expect("rendered");
    assert_ne!(sky.pixels, clear.pixels, "the exported clouds drew nothing");
    // A technique that draws no voxel grid says so.
    let args = [
        "export",
        "vdb.toml",
        "--technique",
        "particles",
        "--resolution",
        "4",
        "--vdb",
        "again.vdb",
    ];
    let run = cloudscape(scratch.path(), &args, false);
    assert!(run.success, "{}", run.stderr);
    let note = "note: particles do not draw the scene's [[volumes]] grids; the ray marcher does";
    assert!(run.stderr.contains(note), "{}", run.stderr);
}

/// Bytes of a dense 256^3 grid of half floats (the GPU's 3D texture of such a grid).
const DENSE_256_BYTES: usize = 256 * 256 * 256 * 2;

#[test]
fn a_sparse_1024_cloud_loads_and_renders_in_less_memory_than_a_dense_256_grid() {
    let Some(python) = python_or_skip() else {
        return;
    };
    let scratch = Scratch::new("vdb-sparse");
    run_script(
        python,
        &["write-sparse", &scratch.path().display().to_string()],
        "",
    );
    let expected = description(scratch.path(), "sparse_1024");
    let grid = assert_read_as_openvdb_reads(scratch.path(), "sparse_1024");
    let span = IVec3::from(expected.max) - IVec3::from(expected.min) + 1;
    assert!(
        span.min_element() > 900,
        "the puffs span {span} voxels, not the 1024^3 box"
    );
    let bricks = BrickGrid::from_sparse(&grid.voxels).expect("bricks");
    eprintln!(
        "sparse 1024^3: {} active voxels, {} bricks, {:.1} MiB; a dense 256^3 grid: {:.1} MiB",
        expected.active_voxels,
        bricks.stored_bricks(),
        bricks.bytes() as f64 / (1 << 20) as f64,
        DENSE_256_BYTES as f64 / (1 << 20) as f64
    );
    assert!(bricks.bytes() < DENSE_256_BYTES);
    // Drawn from outside its 4 km box, looking at its middle.
    let scene = "layers = []\n[[volumes]]\npath = \"sparse_1024.vdb\"\nextinction_per_m = 0.02\n\
        [camera]\nposition_m = [-3000.0, 2500.0, 6000.0]\nlook_at_m = [2048.0, 2048.0, 2048.0]\n";
    std::fs::write(scratch.join("sparse.toml"), scene).unwrap();
    let mut args = vec!["render", "sparse.toml", "--out", "sparse.png"];
    args.extend(TINY);
    let run = cloudscape(scratch.path(), &args, true);
    assert!(run.success, "{}", run.stderr);
    let empty = scene.split("[[volumes]]").next().unwrap().to_string()
        + &scene[scene.find("[camera]").unwrap()..];
    std::fs::write(scratch.join("empty.toml"), empty).unwrap();
    let mut args = vec!["render", "empty.toml", "--out", "empty.png"];
    args.extend(TINY);
    assert!(cloudscape(scratch.path(), &args, true).success);
    let read = |name: &str| {
        LdrImage::read_png(&scratch.join(name))
            .expect("rendered")
            .pixels
    };
    assert_ne!(
        read("sparse.png"),
        read("empty.png"),
        "the sparse cloud drew nothing"
    );
}
