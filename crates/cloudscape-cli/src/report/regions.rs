//! Errors by region: HDR-FLIP and the luminance ratio over the pixels that show cloud, clear
//! sky, ground or the sun's neighbourhood ([`cloudscape_reference::regions`]), beside the
//! whole-image figures, so a change can be judged where it acts.

use anyhow::Result;
use cloudscape::field::PlanetGeometry;
use cloudscape::frame::Frame;
use cloudscape::image::{HdrImage, hdr_flip_errors};
use cloudscape::scene::SceneDocument;
use cloudscape_reference::regions::{Region, classify};
use glam::UVec2;

/// One image's error over one region.
#[derive(Clone, Copy, Debug)]
pub struct RegionError {
    /// The region.
    pub region: Region,
    /// Share of the image's pixels in it.
    pub share: f64,
    /// Mean HDR-FLIP over its pixels (None where it has none).
    pub flip_mean: Option<f64>,
    /// Its mean luminance in the image over that in the reference.
    pub luminance_ratio: Option<f64>,
}

/// An image's errors by region, and its luminance ratio outside the sun's neighbourhood.
#[derive(Clone, Debug)]
pub struct RegionErrors {
    /// One per [`Region::ALL`].
    pub regions: Vec<RegionError>,
    /// Mean luminance ratio over every pixel but the sun's neighbourhood.
    pub luminance_ratio_without_sun: Option<f64>,
}

impl RegionErrors {
    /// `test` against `reference` over the pixels' `regions`.
    pub fn of(reference: &HdrImage, test: &HdrImage, regions: &[Region]) -> Result<RegionErrors> {
        let flip = hdr_flip_errors(reference, test)?;
        let over = |keep: &dyn Fn(Region) -> bool| {
            let pixels: Vec<usize> = (0..regions.len()).filter(|&i| keep(regions[i])).collect();
            let n = pixels.len() as f64;
            let mean = |f: &dyn Fn(usize) -> f64| pixels.iter().map(|&i| f(i)).sum::<f64>() / n;
            let flip_mean = (n > 0.0).then(|| mean(&|i| f64::from(flip[i])));
            let reference_luminance = mean(&|i| reference.luminance(i));
            let ratio = (n > 0.0 && reference_luminance > 0.0)
                .then(|| mean(&|i| test.luminance(i)) / reference_luminance);
            (n / regions.len().max(1) as f64, flip_mean, ratio)
        };
        let regions_out = Region::ALL
            .iter()
            .map(|&region| {
                let (share, flip_mean, luminance_ratio) = over(&|r| r == region);
                RegionError {
                    region,
                    share,
                    flip_mean,
                    luminance_ratio,
                }
            })
            .collect();
        Ok(RegionErrors {
            regions: regions_out,
            luminance_ratio_without_sun: over(&|r| r != Region::Sun).2,
        })
    }

    /// The figures of `region`.
    pub fn get(&self, region: Region) -> RegionError {
        *self
            .regions
            .iter()
            .find(|r| r.region == region)
            .expect("every region is measured")
    }
}

/// The region of every pixel of `doc`'s frame at its render size, from the cloud mask the path
/// tracer recorded in `reference`'s alpha.
pub fn of_scene(doc: &SceneDocument, reference: &HdrImage) -> Vec<Region> {
    let scene = &doc.scene;
    let frame = Frame::from_scene(scene, UVec2::new(reference.width, reference.height));
    let planet = PlanetGeometry::from_scene(&scene.planet);
    let share: Vec<f32> = reference.pixels.iter().map(|p| p[3]).collect();
    classify(&frame, (&planet, scene.ground.enabled), &share)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 96x16 image of three 32-column blocks of the given values.
    fn image(values: [f32; 3]) -> HdrImage {
        let pixels = (0..96 * 16)
            .map(|i| {
                let v = values[(i % 96) / 32];
                [v, v, v, 1.0]
            })
            .collect();
        HdrImage {
            width: 96,
            height: 16,
            pixels,
        }
    }

    #[test]
    fn each_region_is_measured_on_its_own_pixels() {
        let blocks = [Region::Cloud, Region::Ground, Region::Sun];
        let regions: Vec<Region> = (0..96 * 16).map(|i| blocks[(i % 96) / 32]).collect();
        let reference = image([1.0, 0.5, 1000.0]);
        let test = image([2.0, 0.5, 10.0]);
        let errors = RegionErrors::of(&reference, &test, &regions).expect("same size");
        let cloud = errors.get(Region::Cloud);
        assert!((cloud.share - 1.0 / 3.0).abs() < 1e-9);
        assert!((cloud.luminance_ratio.unwrap() - 2.0).abs() < 1e-6);
        let ground = errors.get(Region::Ground);
        assert!((ground.luminance_ratio.unwrap() - 1.0).abs() < 1e-9);
        let (cloud_flip, ground_flip) = (cloud.flip_mean.unwrap(), ground.flip_mean.unwrap());
        assert!(
            ground_flip < cloud_flip / 3.0,
            "the unchanged ground ({ground_flip}) is far below the doubled cloud ({cloud_flip})"
        );
        assert_eq!(errors.get(Region::ClearSky).flip_mean, None);
        let without_sun = errors.luminance_ratio_without_sun.unwrap();
        assert!((without_sun - 2.5 / 1.5).abs() < 1e-6, "{without_sun}");
    }
}
