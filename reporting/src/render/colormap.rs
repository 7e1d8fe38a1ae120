//! The colour map of the animations: matplotlib's *viridis*, sampled at [`LEVELS`] colours.
//!
//! Viridis is perceptually uniform and its lightness rises monotonically from dark purple
//! (low values) to yellow (high values), so a grey-scale print still reads the right way.
//! A frame only ever uses these [`LEVELS`] colours for values, which lets the GIF writer keep
//! one fixed palette for the whole animation (no per-frame colour shifts).

/// Number of distinct colours a value can take.
pub const LEVELS: usize = 128;

/// Viridis at t = 0, 0.1, …, 1 (matplotlib's table, rounded to 8-bit sRGB).
const STOPS: [[u8; 3]; 11] = [
    [68, 1, 84],
    [72, 36, 117],
    [65, 68, 135],
    [53, 95, 141],
    [42, 120, 142],
    [33, 145, 140],
    [34, 168, 132],
    [68, 191, 112],
    [122, 209, 81],
    [189, 223, 38],
    [253, 231, 37],
];

/// Viridis sampled at [`LEVELS`] evenly spaced points, from the lowest value to the highest.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Colormap {
    colors: [[u8; 3]; LEVELS],
}

impl Colormap {
    /// The sampled viridis map.
    pub fn viridis() -> Colormap {
        let mut colors = [[0; 3]; LEVELS];
        for (k, c) in colors.iter_mut().enumerate() {
            *c = interpolate(k as f64 / (LEVELS - 1) as f64);
        }
        Colormap { colors }
    }

    /// The colour of `t`, a fraction of the scale: 0 is the lowest colour, 1 the highest;
    /// values outside [0, 1] are clamped and NaN gives the lowest colour.
    pub fn color(&self, t: f64) -> [u8; 3] {
        self.colors[level(t)]
    }

    /// Every colour, lowest first.
    pub fn colors(&self) -> &[[u8; 3]] {
        &self.colors
    }
}

/// Which of the [`LEVELS`] colours `t` falls on (nearest level; clamped; NaN → 0).
fn level(t: f64) -> usize {
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    (t * (LEVELS - 1) as f64).round() as usize
}

/// Viridis at `t` in [0, 1], linearly interpolated between the stops.
fn interpolate(t: f64) -> [u8; 3] {
    let pos = t * (STOPS.len() - 1) as f64;
    let k = (pos.floor() as usize).min(STOPS.len() - 2);
    let f = pos - k as f64;
    let (a, b) = (STOPS[k], STOPS[k + 1]);
    [0, 1, 2].map(|c| (f64::from(a[c]) + f * (f64::from(b[c]) - f64::from(a[c]))).round() as u8)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Relative luminance (Rec. 709 weights on the 8-bit values), enough to order colours.
    fn luminance(c: [u8; 3]) -> f64 {
        0.2126 * f64::from(c[0]) + 0.7152 * f64::from(c[1]) + 0.0722 * f64::from(c[2])
    }

    #[test]
    fn the_ends_of_the_scale_are_the_ends_of_viridis() {
        let map = Colormap::viridis();
        assert_eq!(map.color(0.0), [68, 1, 84]);
        assert_eq!(map.color(1.0), [253, 231, 37]);
        assert_eq!(map.colors().len(), LEVELS);
    }

    #[test]
    fn brightness_rises_with_the_value() {
        let map = Colormap::viridis();
        for pair in map.colors().windows(2) {
            assert!(
                luminance(pair[1]) > luminance(pair[0]),
                "{:?} is not brighter than {:?}",
                pair[1],
                pair[0]
            );
        }
    }

    #[test]
    fn values_off_the_scale_are_clamped_and_nan_is_the_lowest_colour() {
        let map = Colormap::viridis();
        assert_eq!(map.color(-3.0), map.color(0.0));
        assert_eq!(map.color(7.0), map.color(1.0));
        assert_eq!(map.color(f64::NAN), map.color(0.0));
        assert_eq!(map.color(f64::INFINITY), map.color(1.0));
    }
}
