//! The report's chart: error against frame time, one point per technique and quality preset (the
//! mean over the canonical scenes), with each scene's own point faint behind it, so a reader sees
//! at a glance how much realism each technique buys per millisecond.

use anyhow::{Context, Result, anyhow};
use plotters::prelude::*;
use plotters::style::FontStyle;
use std::path::Path;
use std::sync::OnceLock;

/// Chart size, pixels.
const SIZE_PX: (u32, u32) = (960, 600);

/// Where a point's label goes, pixels from the point: above and below in turn, so neighbours'
/// labels do not overlap.
const LABEL_OFFSETS_PX: [(i32, i32); 2] = [(8, -24), (8, 8)];

/// One technique at one setting.
#[derive(Clone, Debug, PartialEq)]
pub struct ChartSeries {
    /// Its name, written beside its point.
    pub label: String,
    /// Which technique it is, for its colour: 0 ray marcher, 1 particles, 2 sprites.
    pub family: usize,
    /// How far along its family's presets it is, 0..1, for its shade.
    pub shade: f64,
    /// (frame time in ms, HDR-FLIP) on each scene.
    pub scenes: Vec<(f64, f64)>,
}

impl ChartSeries {
    /// Its point: the median frame time and the mean HDR-FLIP over the scenes.
    pub fn summary(&self) -> (f64, f64) {
        let mut times: Vec<f64> = self.scenes.iter().map(|s| s.0).collect();
        times.sort_by(f64::total_cmp);
        let median = times.get(times.len() / 2).copied().unwrap_or(0.0);
        let mean = self.scenes.iter().map(|s| s.1).sum::<f64>() / self.scenes.len().max(1) as f64;
        (median, mean)
    }
}

/// Registers the chart font once: Ubuntu Light, the font egui's default fonts carry in the
/// binary (`epaint_default_fonts`), so the chart needs no font installed on the machine and
/// looks the same on every one.
fn register_font() -> Result<()> {
    static FONT: OnceLock<Result<(), String>> = OnceLock::new();
    FONT.get_or_init(|| {
        let bytes = epaint_default_fonts::UBUNTU_LIGHT;
        plotters::style::register_font("sans-serif", FontStyle::Normal, bytes)
            .map_err(|_| "Ubuntu Light could not be read as a font".to_string())
    })
    .clone()
    .map_err(|e| anyhow!(e))
}

/// The colour of a family at a shade: the ray marcher's presets from light to deep blue, the
/// particles orange, the sprites green, the ray marcher with the slab model purple.
fn colour(family: usize, shade: f64) -> RGBColor {
    let mix = |a: (f64, f64, f64), b: (f64, f64, f64)| {
        let t = shade.clamp(0.0, 1.0);
        let c = |x: f64, y: f64| (x + (y - x) * t) as u8;
        RGBColor(c(a.0, b.0), c(a.1, b.1), c(a.2, b.2))
    };
    match family {
        0 => mix((120.0, 170.0, 230.0), (20.0, 50.0, 140.0)),
        1 => RGBColor(230, 120, 30),
        2 => RGBColor(40, 150, 70),
        _ => RGBColor(150, 60, 160),
    }
}

/// Draws `series` as a PNG at `path`, titled `caption`.
pub fn draw(path: &Path, series: &[ChartSeries], caption: &str) -> Result<()> {
    register_font()?;
    let all = series.iter().flat_map(|s| s.scenes.iter());
    let (mut t_min, mut t_max, mut e_max) = (f64::MAX, 0.0f64, 0.0f64);
    for &(t, e) in all {
        (t_min, t_max, e_max) = (t_min.min(t), t_max.max(t), e_max.max(e));
    }
    if series.is_empty() || t_max <= 0.0 {
        return Err(anyhow!("no measurements to chart"));
    }
    let root = BitMapBackend::new(path, SIZE_PX).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(caption, ("sans-serif", 22))
        .margin(16)
        .x_label_area_size(48)
        .y_label_area_size(64)
        .build_cartesian_2d(
            ((t_min * 0.7).max(1e-3)..t_max * 3.0).log_scale(),
            0.0..(e_max * 1.1).max(0.05),
        )?;
    chart
        .configure_mesh()
        .x_desc("frame time, ms (log scale)")
        .y_desc("HDR-FLIP against the path tracer (lower is better)")
        .x_labels(8)
        .x_label_formatter(&|ms| format!("{ms:.0}"))
        .y_label_formatter(&|e| format!("{e:.2}"))
        .light_line_style(WHITE)
        .label_style(("sans-serif", 15))
        .axis_desc_style(("sans-serif", 17))
        .draw()?;
    for (i, s) in series.iter().enumerate() {
        let c = colour(s.family, s.shade);
        chart.draw_series(
            s.scenes
                .iter()
                .map(|&p| Circle::new(p, 3, c.mix(0.3).filled())),
        )?;
        let label = s.label.clone();
        chart.draw_series(std::iter::once(
            EmptyElement::at(s.summary())
                + Circle::new((0, 0), 7, c.filled())
                + Text::new(
                    label,
                    LABEL_OFFSETS_PX[i % 2],
                    ("sans-serif", 15).into_font(),
                ),
        ))?;
    }
    root.present()
        .with_context(|| format!("writing {}", path.display()))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn summaries_are_the_median_time_and_the_mean_error() {
        let s = ChartSeries {
            label: "x".into(),
            family: 0,
            shade: 0.0,
            scenes: vec![(3.0, 0.1), (1.0, 0.2), (2.0, 0.6)],
        };
        let (t, e) = s.summary();
        assert_eq!(t, 2.0);
        assert!((e - 0.3).abs() < 1e-12);
    }

    /// The chart is drawn: a PNG of the stated size whose pixels are not all white.
    #[test]
    fn the_chart_draws_every_series() {
        let dir = std::env::temp_dir().join(format!("cloudscape-chart-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("a temporary directory");
        let path = dir.join("chart.png");
        let series: Vec<ChartSeries> = (0..3)
            .map(|family| ChartSeries {
                label: format!("technique {family}"),
                family,
                shade: 0.5,
                scenes: vec![(10.0 * (family + 1) as f64, 0.1), (5.0, 0.2)],
            })
            .collect();
        draw(&path, &series, "test").expect("the chart draws");
        let image = cloudscape::image::LdrImage::read_png(&path).expect("a PNG");
        assert_eq!((image.width, image.height), SIZE_PX);
        let coloured = image
            .pixels
            .iter()
            .filter(|p| p[0] != p[1] || p[1] != p[2])
            .count();
        assert!(coloured > 100, "{coloured} coloured pixels");
        std::fs::remove_dir_all(&dir).ok();
    }
}
