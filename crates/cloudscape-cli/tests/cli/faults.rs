//! Faults: an unwritable output path, a full disk and Ctrl-C mid-render each end with a clear
//! message and leave no partial file; the soak holds its memory; the start-up on Vulkan prints no
//! libwayland noise when `XDG_RUNTIME_DIR` is unset.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::sync::mpsc;
use std::time::Duration;

use crate::needs;
use crate::support::{Scratch, TINY, cloudscape, command, run};
use cloudscape::image::HdrImage;

/// Longest wait for a command to reach the point where it is interrupted.
const CUE_TIMEOUT: Duration = Duration::from_secs(300);

/// A render that takes many seconds on a software adapter: time to interrupt it.
const SLOW: [&str; 8] = [
    "--width",
    "320",
    "--height",
    "180",
    "--set",
    "render.quality=ultra",
    "--set",
    "render.samples_per_pixel=64",
];

/// Starts `cloudscape args...` in `dir`, waits until its standard error has a line holding `cue`,
/// sends it SIGINT and waits for it: its exit status and everything it wrote to standard error.
fn interrupt_after(dir: &Path, args: &[&str], cue: &'static str) -> (ExitStatus, String) {
    let mut child = command(dir, args, true)
        .stderr(Stdio::piped())
        .stdout(Stdio::null())
        .spawn()
        .expect("start the cloudscape binary");
    let stderr = child.stderr.take().expect("piped stderr");
    let (cued, cue_seen) = mpsc::channel();
    let reader = std::thread::spawn(move || {
        let mut text = String::new();
        for line in BufReader::new(stderr).lines() {
            let line = line.expect("read stderr");
            if line.contains(cue) {
                let _ = cued.send(());
            }
            text.push_str(&line);
            text.push('\n');
        }
        text
    });
    let seen = cue_seen.recv_timeout(CUE_TIMEOUT);
    let pid = libc::pid_t::try_from(child.id()).expect("a process id");
    // SAFETY: kill(2) takes plain integers; the child is ours and has not been waited for.
    let killed = unsafe { libc::kill(pid, libc::SIGINT) } == 0;
    let status = child.wait().expect("wait for cloudscape");
    let stderr = reader.join().expect("stderr reader");
    assert!(seen.is_ok(), "never printed {cue:?}:\n{stderr}");
    assert!(
        killed,
        "SIGINT not sent: {}",
        std::io::Error::last_os_error()
    );
    (status, stderr)
}

/// `first`, then every group of arguments in order.
fn args<'a>(first: &[&'a str], groups: &[&[&'a str]]) -> Vec<&'a str> {
    let mut all = first.to_vec();
    for group in groups {
        all.extend_from_slice(group);
    }
    all
}

/// Every file under `dir`, recursively.
fn files_under(dir: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).expect("list directory") {
        let path = entry.expect("entry").path();
        if path.is_dir() {
            files.extend(files_under(&path));
        } else {
            files.push(path);
        }
    }
    files
}

#[test]
fn an_unwritable_output_path_is_named_and_nothing_is_written() {
    let scratch = Scratch::new("unwritable");
    let args = args(&["render"], &[&TINY, &["--out", "no-such-dir/out.png"]]);
    let run = cloudscape(scratch.path(), &args, true);
    assert!(!run.success, "{}", run.stderr);
    assert!(
        run.stderr.contains("no-such-dir/out.png") && run.stderr.contains("No such file"),
        "{}",
        run.stderr
    );
    assert!(scratch.file_names().is_empty());
}

/// A tmpfs of a few kilobytes mounted on a scratch directory, unmounted when dropped.
struct TinyDisk(Scratch);

impl TinyDisk {
    /// Mounts it; None, reported by [`needs::met`], when the machine will not (mounting a tmpfs
    /// needs Linux and root, as CI has).
    fn mount(size_kib: u32) -> Option<TinyDisk> {
        let scratch = Scratch::new("full-disk");
        let mounted = Command::new("mount")
            .args(["-t", "tmpfs", "-o", &format!("size={size_kib}k"), "tmpfs"])
            .arg(scratch.path())
            .stderr(Stdio::null())
            .status()
            .is_ok_and(|status| status.success());
        let missing = (!mounted).then(|| needs::Missing {
            what: "a tmpfs mount of its own".to_string(),
            remedy: "Linux and root, as in CI".to_string(),
        });
        needs::met(missing).then_some(TinyDisk(scratch))
    }
}

impl Drop for TinyDisk {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(self.0.path()).status();
    }
}

#[test]
fn a_full_disk_is_reported_and_leaves_no_partial_file() {
    let Some(disk) = TinyDisk::mount(4) else {
        return;
    };
    let out = disk.0.join("out.exr");
    let out = out.to_str().expect("a UTF-8 path");
    let args = args(&["render"], &[&TINY, &["--out", out]]);
    let run = cloudscape(Path::new("."), &args, true);
    assert!(!run.success, "{}", run.stderr);
    assert!(
        run.stderr.contains("out.exr") && run.stderr.contains("No space left on device"),
        "{}",
        run.stderr
    );
    assert!(files_under(disk.0.path()).is_empty());
}

#[test]
fn ctrl_c_mid_render_stops_and_writes_nothing() {
    let scratch = Scratch::new("interrupt-render");
    let args = args(&["render"], &[&SLOW, &["--out", "out.exr"]]);
    let (status, stderr) = interrupt_after(scratch.path(), &args, "rendering 320x180");
    assert_eq!(status.code(), Some(130), "{stderr}");
    assert!(
        stderr.contains("interrupted: stopped; no partial file"),
        "{stderr}"
    );
    assert!(scratch.file_names().is_empty());
}

#[test]
fn ctrl_c_mid_animate_leaves_only_whole_frames() {
    let scratch = Scratch::new("interrupt-animate");
    let args = args(&["animate", "--frames", "50", "--out", "frames"], &[&SLOW]);
    let (status, stderr) = interrupt_after(scratch.path(), &args, "adapter:");
    assert_eq!(status.code(), Some(130), "{stderr}");
    assert!(stderr.contains("interrupted"), "{stderr}");
    for file in files_under(scratch.path()) {
        let name = file.file_name().unwrap().to_string_lossy().into_owned();
        assert!(!name.starts_with('.'), "a temporary file is left: {name}");
        cloudscape::image::LdrImage::read_png(&file)
            .unwrap_or_else(|e| panic!("{name} is not whole: {e}"));
    }
}

#[test]
fn ctrl_c_mid_reference_writes_the_image_so_far() {
    let scratch = Scratch::new("interrupt-reference");
    let args = args(
        &["reference", "--spp", "100000", "--pass-spp", "1"],
        &[&TINY, &["--out", "ref.exr"]],
    );
    let (status, stderr) = interrupt_after(scratch.path(), &args, "path tracing");
    assert!(status.success(), "{stderr}");
    assert!(stderr.contains("stopped early"), "{stderr}");
    assert_eq!(
        scratch.file_names().into_iter().collect::<Vec<_>>(),
        ["ref.exr"]
    );
    let image = HdrImage::read(&scratch.join("ref.exr")).expect("a whole EXR");
    assert_eq!((image.width, image.height), (64, 36));
}

#[test]
fn start_up_without_xdg_runtime_dir_prints_no_wayland_noise() {
    let scratch = Scratch::new("no-xdg");
    let args = args(&["render"], &[&TINY, &["--out", "out.png"]]);
    let mut command = command(scratch.path(), &args, true);
    command.env_remove("XDG_RUNTIME_DIR");
    let run = run(command);
    assert!(run.success, "{}", run.stderr);
    assert!(!run.stderr.contains("XDG_RUNTIME_DIR"), "{}", run.stderr);
}

#[test]
fn a_short_soak_keeps_its_memory_and_reports_it() {
    let scratch = Scratch::new("soak");
    let soak = ["--soak", "35", "--soak-edit-every", "5", "--warmup", "2"];
    let args = args(&["bench"], &[&soak, &TINY]);
    let run = cloudscape(scratch.path(), &args, true);
    assert!(run.success, "{}\n{}", run.stdout, run.stderr);
    for figure in ["resident memory", "live wgpu objects", "14 live edits"] {
        assert!(run.stdout.contains(figure), "{figure}:\n{}", run.stdout);
    }
    // 35 frames are one cycle of the seven edits; its figures are progress, logged on stderr.
    assert!(run.stderr.contains("cycle 1: resident"), "{}", run.stderr);
}
