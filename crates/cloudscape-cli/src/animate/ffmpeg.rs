//! An MP4 preview encoded by `ffmpeg`, when it is on PATH, from display frames piped to it.

use anyhow::{Context, Result, anyhow};
use cloudscape::fsutil::PendingFile;
use cloudscape::image::LdrImage;
use glam::UVec2;
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, Command, Stdio};

/// A running `ffmpeg` that turns raw RGBA frames on its standard input into an H.264 (or the
/// build's default) MP4. It writes a hidden temporary file that [`Mp4Writer::finish`] renames;
/// dropped unfinished, it stops `ffmpeg` and removes that file.
pub struct Mp4Writer {
    child: Child,
    stdin: Option<ChildStdin>,
    temporary: PathBuf,
    /// Lists the temporary file, so that Ctrl-C removes it.
    pending: PendingFile,
    path: PathBuf,
}

impl Mp4Writer {
    /// Starts `ffmpeg` for frames of `size` pixels at `fps` frames per second, writing `path`;
    /// `None` when `ffmpeg` is not on PATH.
    pub fn start(path: &Path, size: UVec2, fps: f32) -> Result<Option<Mp4Writer>> {
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned());
        let temporary = path.with_file_name(format!(".{}.partial", name.unwrap_or_default()));
        let pending = PendingFile::list(&temporary).context("starting ffmpeg")?;
        let spawned = Command::new("ffmpeg")
            .args(["-hide_banner", "-nostats", "-loglevel", "error", "-y"])
            .args(["-f", "rawvideo", "-pix_fmt", "rgba"])
            .args(["-video_size", &format!("{}x{}", size.x, size.y)])
            .args(["-framerate", &fps.to_string(), "-i", "pipe:0"])
            // yuv420p (what players expect) needs even sides.
            .args([
                "-vf",
                "scale=trunc(iw/2)*2:trunc(ih/2)*2",
                "-pix_fmt",
                "yuv420p",
            ])
            .args(["-movflags", "+faststart", "-f", "mp4"])
            .arg(&temporary)
            .stdin(Stdio::piped())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn();
        let mut child = match spawned {
            Err(error) if error.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            other => other.context("starting ffmpeg")?,
        };
        Ok(Some(Mp4Writer {
            stdin: child.stdin.take(),
            child,
            temporary,
            pending,
            path: path.to_path_buf(),
        }))
    }

    /// Sends one frame (of the size given to [`Mp4Writer::start`]).
    pub fn push(&mut self, frame: &LdrImage) -> Result<()> {
        let stdin = self.stdin.as_mut().context("ffmpeg's input is closed")?;
        stdin
            .write_all(frame.pixels.as_flattened())
            .context("ffmpeg stopped reading frames")
    }

    /// Ends the input, waits for `ffmpeg` and moves the finished MP4 into place.
    pub fn finish(mut self) -> Result<PathBuf> {
        drop(self.stdin.take());
        let mut messages = String::new();
        if let Some(mut stderr) = self.child.stderr.take() {
            // What ffmpeg said only explains a failure; a failure to read it loses no frames.
            let _ = stderr.read_to_string(&mut messages);
        }
        let status = self.child.wait().context("waiting for ffmpeg")?;
        if !status.success() {
            return Err(anyhow!("ffmpeg failed ({status}): {}", messages.trim()));
        }
        self.pending
            .rename_to(&self.path)
            .with_context(|| format!("moving the MP4 to {}", self.path.display()))?;
        Ok(self.path.clone())
    }
}

impl Drop for Mp4Writer {
    /// Stops an unfinished `ffmpeg` and removes its partial file; after [`Mp4Writer::finish`] the
    /// process has exited and the file is renamed, so both steps find nothing to do.
    fn drop(&mut self) {
        drop(self.stdin.take());
        let _ = self.child.kill();
        let _ = self.child.wait();
        let _ = std::fs::remove_file(&self.temporary);
    }
}
