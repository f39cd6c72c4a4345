//! Frame-to-frame change of a sequence, and the part of it a converged sequence does not have.
//!
//! Both work on Rec. 709 luma of the tone-mapped, sRGB-encoded frames ([`LdrImage::luma`], in
//! [0, 1]): the change a viewer sees.
//!
//! [`LdrImage::luma`]: cloudscape::image::LdrImage::luma

/// The luma of two consecutive frames of one sequence, `(previous, current)`.
pub type LumaPair<'a> = (&'a [f32], &'a [f32]);

/// Frame change: the mean over pixels of `|Y'_t - Y'_{t-1}|`, with `Y'` the luma of frame `t`.
/// Camera motion and moving clouds change frames; so do noise and flicker.
pub fn mean_change((previous, current): LumaPair) -> f64 {
    mean_abs(previous.iter().zip(current).map(|(p, c)| c - p))
}

/// Flicker: the mean over pixels of `|(X_t - X_{t-1}) - (C_t - C_{t-1})|`, with `X` the luma of
/// the measured sequence and `C` that of the converged sequence of the same frames. The converged
/// change is what the motion explains; what is left is change the converged sequence does not
/// have: noise that differs from frame to frame, flicker, and history that lags (ghosting).
/// 0 for a sequence that changes exactly as the converged one does.
pub fn flicker(measured: LumaPair, converged: LumaPair) -> f64 {
    let (x_prev, x) = measured;
    let (c_prev, c) = converged;
    let steps = x.iter().zip(x_prev).zip(c.iter().zip(c_prev));
    mean_abs(steps.map(|((x, xp), (c, cp))| (x - xp) - (c - cp)))
}

/// Mean of the absolute values (0 for none).
fn mean_abs(values: impl Iterator<Item = f32>) -> f64 {
    let (sum, count) = values.fold((0.0, 0u64), |(sum, n), v| (sum + f64::from(v.abs()), n + 1));
    if count == 0 { 0.0 } else { sum / count as f64 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn change_is_the_mean_absolute_step() {
        assert!((mean_change((&[0.0, 0.5, 1.0], &[0.5, 0.5, 0.0])) - 0.5).abs() < 1e-9);
        assert_eq!(mean_change((&[], &[])), 0.0);
    }

    #[test]
    fn change_the_converged_sequence_shares_is_not_flicker() {
        let (before, after) = ([0.2, 0.4], [0.6, 0.1]);
        assert_eq!(flicker((&before, &after), (&before, &after)), 0.0);
        // Noise toggling one pixel by 0.1 while the converged frame holds still.
        let noisy = [0.3, 0.4];
        let flicker = flicker((&before, &noisy), (&before, &before));
        assert!((flicker - 0.05).abs() < 1e-6, "{flicker}");
    }

    #[test]
    fn lagging_history_is_flicker_too() {
        // The converged frame brightens; a sequence that stays put misses that change.
        let lag = flicker((&[0.2], &[0.2]), (&[0.2], &[0.5]));
        assert!((lag - 0.3).abs() < 1e-6, "{lag}");
    }
}
