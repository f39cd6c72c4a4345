//! Image comparison by relative MSE on linear radiance; FLIP on display images is in `flip`.

use super::{HdrImage, ImageError, check_size};

/// Checks both images and that they have the same size.
pub(super) fn check_same_size(
    reference: (u32, u32, usize),
    test: (u32, u32, usize),
) -> Result<(), ImageError> {
    check_size(reference.0, reference.1, reference.2)?;
    check_size(test.0, test.1, test.2)?;
    if (reference.0, reference.1) != (test.0, test.1) {
        return Err(ImageError::SizeMismatch {
            reference: (reference.0, reference.1),
            test: (test.0, test.1),
        });
    }
    Ok(())
}

/// Regulariser of the relative MSE denominator, in squared radiance units (physics.md).
const RELATIVE_MSE_EPSILON: f64 = 0.01;

/// Relative mean squared error of linear radiance, the mean over pixels and RGB channels of
/// `(x - y)^2 / (y^2 + 0.01)` with `x` the test and `y` the reference value (Rousselle et al.
/// 2011, "Adaptive Sampling and Reconstruction using Greedy Error Minimization"). Alpha is ignored.
pub fn relative_mse(reference: &HdrImage, test: &HdrImage) -> Result<f64, ImageError> {
    let size = |i: &HdrImage| (i.width, i.height, i.pixels.len());
    check_same_size(size(reference), size(test))?;
    let total: f64 = reference
        .pixels
        .iter()
        .zip(&test.pixels)
        .flat_map(|(r, t)| (0..3).map(move |c| (f64::from(r[c]), f64::from(t[c]))))
        .map(|(y, x)| (x - y) * (x - y) / (y * y + RELATIVE_MSE_EPSILON))
        .sum();
    Ok(total / (3 * reference.pixels.len()) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn size_mismatch_is_an_error() {
        let (a, b) = (HdrImage::new(2, 2), HdrImage::new(2, 1));
        assert!(matches!(
            relative_mse(&a, &b),
            Err(ImageError::SizeMismatch { .. })
        ));
    }

    #[test]
    fn relative_mse_matches_definition() {
        let reference = HdrImage {
            width: 1,
            height: 2,
            pixels: vec![[1.0, 0.0, 2.0, 1.0]; 2],
        };
        assert_eq!(
            relative_mse(&reference, &reference).expect("same size"),
            0.0
        );
        let mut test = reference.clone();
        test.pixels[0] = [2.0, 0.1, 2.0, 0.0];
        // Pixel 0: (1 / 1.01) + (0.01 / 0.01) + 0, pixel 1: 0; over 6 values.
        let expected = (1.0 / 1.01 + 1.0) / 6.0;
        let got = relative_mse(&reference, &test).expect("same size");
        assert!((got - expected).abs() < 1e-7, "{got} vs {expected}");
    }
}
