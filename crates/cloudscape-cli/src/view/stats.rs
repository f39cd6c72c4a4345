//! What each frame costs, measured without waiting for the GPU: the CPU's frame time, the GPU's
//! wall time per frame (from the queue's completion callbacks) and, where the adapter has
//! timestamp queries, the GPU time of each pass a frame late.

use std::collections::VecDeque;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// How much history the frame-time graph shows.
pub const HISTORY: Duration = Duration::from_secs(5);

/// One frame's times.
#[derive(Clone, Copy, Debug)]
pub struct FrameTime {
    /// When the frame started.
    pub at: Instant,
    /// Time since the previous frame started, ms.
    pub cpu_ms: f64,
}

/// The frame times of the last [`HISTORY`], and the GPU's wall time per frame.
pub struct FrameStats {
    frames: VecDeque<FrameTime>,
    last_start: Option<Instant>,
    /// The first frame's start, and the frames started since.
    first_start: Option<Instant>,
    count: u64,
    /// Completion times of submitted frames, pushed by the queue's callbacks.
    done: Arc<Mutex<VecDeque<(Instant, Instant)>>>,
    /// When the GPU last finished a frame.
    last_done: Option<Instant>,
    /// The GPU's busy time of the newest finished frame, ms.
    pub gpu_wall_ms: Option<f64>,
}

impl FrameStats {
    /// No frames yet.
    pub fn new() -> FrameStats {
        FrameStats {
            frames: VecDeque::new(),
            last_start: None,
            first_start: None,
            count: 0,
            done: Arc::new(Mutex::new(VecDeque::new())),
            last_done: None,
            gpu_wall_ms: None,
        }
    }

    /// Marks the start of a frame.
    pub fn start_frame(&mut self) {
        let now = Instant::now();
        self.first_start.get_or_insert(now);
        self.count += 1;
        if let Some(last) = self.last_start {
            self.frames.push_back(FrameTime {
                at: now,
                cpu_ms: (now - last).as_secs_f64() * 1e3,
            });
        }
        self.last_start = Some(now);
        while self.frames.front().is_some_and(|f| now - f.at > HISTORY) {
            self.frames.pop_front();
        }
        self.collect_gpu();
    }

    /// Asks the queue to report when the work submitted so far (this frame's) is done; call right
    /// after submitting a frame.
    pub fn watch_submission(&self, queue: &wgpu::Queue) {
        let done = self.done.clone();
        let submitted = Instant::now();
        queue.on_submitted_work_done(move || {
            if let Ok(mut done) = done.lock() {
                done.push_back((submitted, Instant::now()));
            }
        });
    }

    /// The GPU's busy time per finished frame: from when it could start the frame (its
    /// submission, or the end of the frame before) to its end.
    fn collect_gpu(&mut self) {
        let Ok(mut done) = self.done.lock() else {
            return;
        };
        for (submitted, finished) in done.drain(..) {
            let start = self.last_done.map_or(submitted, |last| last.max(submitted));
            self.gpu_wall_ms = Some((finished - start).as_secs_f64() * 1e3);
            self.last_done = Some(finished);
        }
    }

    /// The frames of the last [`HISTORY`], oldest first.
    pub fn frames(&self) -> &VecDeque<FrameTime> {
        &self.frames
    }

    /// The whole run in words: frames, mean frame time and rate since the first frame (the first
    /// frame's set-up included), and the GPU's newest wall time.
    pub fn summary(&self) -> String {
        let elapsed_s = self
            .first_start
            .map_or(0.0, |first| first.elapsed().as_secs_f64());
        let frames = self.count.max(1) as f64;
        let gpu = self.gpu_wall_ms.map_or(String::new(), |ms| {
            format!(", GPU wall {ms:.1} ms per frame")
        });
        format!(
            "{} frames in {elapsed_s:.2} s: {:.1} ms per frame, {:.2} fps{gpu}",
            self.count,
            elapsed_s * 1e3 / frames,
            frames / elapsed_s.max(1e-9)
        )
    }

    /// Mean frame time over the last second, ms.
    pub fn mean_ms(&self) -> Option<f64> {
        let now = self.last_start?;
        let recent: Vec<f64> = self
            .frames
            .iter()
            .filter(|f| now - f.at <= Duration::from_secs(1))
            .map(|f| f.cpu_ms)
            .collect();
        (!recent.is_empty()).then(|| recent.iter().sum::<f64>() / recent.len() as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_times_are_the_intervals_between_starts_and_age_out() {
        let mut stats = FrameStats::new();
        stats.start_frame();
        assert!(stats.frames().is_empty());
        std::thread::sleep(Duration::from_millis(5));
        stats.start_frame();
        let first = stats.frames()[0].cpu_ms;
        assert!(first >= 5.0, "{first}");
        assert!(stats.mean_ms().unwrap() >= 5.0);
        stats.frames.front_mut().unwrap().at -= HISTORY * 2;
        stats.start_frame();
        assert_eq!(stats.frames().len(), 1);
    }

    #[test]
    fn gpu_wall_time_starts_at_the_later_of_submission_and_the_previous_end() {
        let mut stats = FrameStats::new();
        let t0 = Instant::now();
        let ms = Duration::from_millis;
        stats.done.lock().unwrap().extend([
            (t0, t0 + ms(10)),
            (t0 + ms(2), t0 + ms(25)),
            (t0 + ms(40), t0 + ms(45)),
        ]);
        stats.collect_gpu();
        let wall = stats.gpu_wall_ms.unwrap();
        assert!((wall - 5.0).abs() < 1e-6, "{wall}");
    }
}
