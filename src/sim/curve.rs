//! Piecewise-linear material curves (stress–strain, moment–curvature).
//!
//! A curve is a list of measured points `(x, y)` with strictly increasing `x`. Between
//! points it interpolates linearly; outside the measured range it extrapolates with the
//! slope of the nearest end segment. Material curves must pass through the origin (an
//! unloaded fabric carries no stress), and their slopes must be positive so that the
//! energy they define is convex: a fabric that softens to zero stiffness would let the
//! implicit solver's Newton steps run away.
//!
//! Compression: a tensile curve measured only for `x ≥ 0` continues into compression with
//! its first segment's slope. To model a fabric that is softer in compression, give
//! points with negative strain.

use thiserror::Error;

/// Why a list of points is not a usable material curve.
#[derive(Debug, Error, PartialEq)]
pub enum CurveError {
    #[error("needs at least 2 points, got {0}; give e.g. [[0.0, 0.0], [0.01, 10.0]]")]
    TooFewPoints(usize),
    #[error("point {index} is not finite; every strain and stress must be a finite number")]
    NotFinite { index: usize },
    #[error(
        "points must be sorted by strictly increasing strain: point {index} (strain {x:?}) \
         does not come after {previous:?}; sort the points by their first value"
    )]
    Unsorted { index: usize, x: f64, previous: f64 },
    #[error(
        "segment {index} (from strain {x0:?} to {x1:?}) has slope {slope:?}, but every segment must \
         rise (slope > 0) so the material stays stable; make each stress larger than the one before"
    )]
    NonIncreasing { index: usize, x0: f64, x1: f64, slope: f64 },
    #[error("the curve must pass through [0.0, 0.0] (an unloaded fabric carries no stress); add that point")]
    MissingOrigin,
}

/// A validated piecewise-linear curve `y(x)` with the energy `∫₀ˣ y dx` precomputed at its knots.
#[derive(Debug, Clone, PartialEq)]
pub struct PiecewiseLinear {
    xs: Vec<f64>,
    ys: Vec<f64>,
    /// `integral_at_knot[i] = ∫₀^{xs[i]} y dx`.
    integral_at_knot: Vec<f64>,
    /// `slopes[i]`: segment i's slope, divided out once rather than at every evaluation.
    slopes: Vec<f64>,
}

impl PiecewiseLinear {
    /// Builds a material curve: sorted, rising, through the origin.
    pub fn new_material(points: &[[f64; 2]]) -> Result<Self, CurveError> {
        if points.len() < 2 {
            return Err(CurveError::TooFewPoints(points.len()));
        }
        for (index, p) in points.iter().enumerate() {
            if !p[0].is_finite() || !p[1].is_finite() {
                return Err(CurveError::NotFinite { index });
            }
            if index > 0 && p[0] <= points[index - 1][0] {
                return Err(CurveError::Unsorted { index, x: p[0], previous: points[index - 1][0] });
            }
        }
        let slopes: Vec<f64> = points.windows(2).map(|pair| (pair[1][1] - pair[0][1]) / (pair[1][0] - pair[0][0])).collect();
        if let Some(index) = slopes.iter().position(|&slope| slope <= 0.0) {
            let slope = slopes[index];
            return Err(CurveError::NonIncreasing { index, x0: points[index][0], x1: points[index + 1][0], slope });
        }
        if !points.iter().any(|p| p[0] == 0.0 && p[1] == 0.0) {
            return Err(CurveError::MissingOrigin);
        }
        let xs: Vec<f64> = points.iter().map(|p| p[0]).collect();
        let ys: Vec<f64> = points.iter().map(|p| p[1]).collect();
        let origin = xs.iter().position(|&x| x == 0.0).expect("origin checked above");
        // Trapezoid areas accumulated outwards from the origin in both directions.
        let mut integral_at_knot = vec![0.0; xs.len()];
        for i in origin + 1..xs.len() {
            integral_at_knot[i] = integral_at_knot[i - 1] + 0.5 * (ys[i] + ys[i - 1]) * (xs[i] - xs[i - 1]);
        }
        for i in (0..origin).rev() {
            integral_at_knot[i] = integral_at_knot[i + 1] - 0.5 * (ys[i] + ys[i + 1]) * (xs[i + 1] - xs[i]);
        }
        Ok(Self { xs, ys, integral_at_knot, slopes })
    }

    /// A straight line through the origin with the given slope (a linear material).
    pub fn linear(slope: f64) -> Self {
        Self::new_material(&[[0.0, 0.0], [1.0, slope]]).expect("a positive slope makes a valid curve")
    }

    /// Index of the segment used at `x` (end segments extend to ±∞).
    fn segment(&self, x: f64) -> usize {
        // The inner knots at or below x, counted without branches: a measured curve has a
        // handful of knots, and a binary search's mispredicted branches cost more than the
        // count (the segment search was 4 % of a landing cloth's profile; docs/performance-log.md,
        // "2026-12-07, late").
        let inner = &self.xs[1..self.xs.len() - 1];
        inner.iter().map(|&knot| usize::from(knot <= x)).sum()
    }

    /// The curve's value `y(x)`.
    pub fn value(&self, x: f64) -> f64 {
        let i = self.segment(x);
        self.ys[i] + self.slope_of_segment(i) * (x - self.xs[i])
    }

    /// The tangent slope `dy/dx` at `x` (the right-hand slope at a knot).
    /// `(value(x), slope(x))` with one search for the segment.
    pub fn value_and_slope(&self, x: f64) -> (f64, f64) {
        let i = self.segment(x);
        let slope = self.slope_of_segment(i);
        (self.ys[i] + slope * (x - self.xs[i]), slope)
    }

    pub fn slope(&self, x: f64) -> f64 {
        self.slope_of_segment(self.segment(x))
    }

    /// The energy `∫₀ˣ y dx`.
    /// `(integral(x), value(x))`, the segment searched once.
    pub fn integral_and_value(&self, x: f64) -> (f64, f64) {
        let i = self.segment(x);
        let (dx, slope) = (x - self.xs[i], self.slope_of_segment(i));
        (self.integral_at_knot[i] + self.ys[i] * dx + 0.5 * slope * dx * dx, self.ys[i] + slope * dx)
    }

    pub fn integral(&self, x: f64) -> f64 {
        let i = self.segment(x);
        let dx = x - self.xs[i];
        self.integral_at_knot[i] + self.ys[i] * dx + 0.5 * self.slope_of_segment(i) * dx * dx
    }

    fn slope_of_segment(&self, i: usize) -> f64 {
        self.slopes[i]
    }

    /// Slope of the first segment that starts at or after zero: the small-strain tensile modulus.
    pub fn initial_slope(&self) -> f64 {
        self.slope(0.0)
    }

    /// The smallest slope over all segments (bounds how soft the material can become).
    pub fn min_slope(&self) -> f64 {
        self.slopes.iter().copied().fold(f64::INFINITY, f64::min)
    }

    /// The largest slope over all segments (bounds how stiff the material can become).
    pub fn max_slope(&self) -> f64 {
        self.slopes.iter().copied().fold(0.0, f64::max)
    }

    /// The measured points, as given.
    pub fn points(&self) -> impl Iterator<Item = [f64; 2]> + '_ {
        self.xs.iter().zip(&self.ys).map(|(&x, &y)| [x, y])
    }

    /// Largest strain among the measured points.
    pub fn max_x(&self) -> f64 {
        *self.xs.last().expect("at least two points")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_zero_and_one_point() {
        assert_eq!(PiecewiseLinear::new_material(&[]), Err(CurveError::TooFewPoints(0)));
        assert_eq!(PiecewiseLinear::new_material(&[[0.0, 0.0]]), Err(CurveError::TooFewPoints(1)));
    }

    #[test]
    fn rejects_unsorted_and_duplicate_strains() {
        let unsorted = PiecewiseLinear::new_material(&[[0.0, 0.0], [0.02, 2.0], [0.01, 3.0]]);
        assert!(matches!(unsorted, Err(CurveError::Unsorted { index: 2, .. })));
        let duplicate = PiecewiseLinear::new_material(&[[0.0, 0.0], [0.0, 1.0]]);
        assert!(matches!(duplicate, Err(CurveError::Unsorted { index: 1, .. })));
    }

    #[test]
    fn rejects_softening_to_zero_and_missing_origin() {
        let flat = PiecewiseLinear::new_material(&[[0.0, 0.0], [0.01, 1.0], [0.02, 1.0]]);
        assert!(matches!(flat, Err(CurveError::NonIncreasing { index: 1, .. })));
        let offset = PiecewiseLinear::new_material(&[[0.0, 1.0], [0.01, 2.0]]);
        assert_eq!(offset, Err(CurveError::MissingOrigin));
        let nan = PiecewiseLinear::new_material(&[[0.0, 0.0], [f64::NAN, 2.0]]);
        assert_eq!(nan, Err(CurveError::NotFinite { index: 1 }));
    }

    #[test]
    fn two_points_is_linear_everywhere() {
        let c = PiecewiseLinear::new_material(&[[0.0, 0.0], [0.01, 10.0]]).unwrap();
        assert_eq!(c.value(0.005), 5.0);
        assert!((c.value(-0.01) + 10.0).abs() < 1e-12, "compression continues the first slope");
        assert!((c.value(0.05) - 50.0).abs() < 1e-9, "tension beyond the data continues the last slope");
        assert!((c.integral(0.01) - 0.05).abs() < 1e-15);
    }

    #[test]
    fn three_points_interpolate_and_integrate() {
        // Slopes 1000 then 4000 N/m with a knee at 1 % strain.
        let c = PiecewiseLinear::new_material(&[[0.0, 0.0], [0.01, 10.0], [0.02, 50.0]]).unwrap();
        assert!((c.value(0.015) - 30.0).abs() < 1e-12);
        assert_eq!(c.slope(0.005), 1000.0);
        assert_eq!(c.slope(0.01), 4000.0, "right-hand slope at a knee");
        assert!((c.slope(0.5) - 4000.0).abs() < 1e-9);
        // ∫₀^0.015: 0.05 over the first segment plus (10+30)/2·0.005.
        assert!((c.integral(0.015) - (0.05 + 0.1)).abs() < 1e-14);
        assert_eq!(c.initial_slope(), 1000.0);
        assert_eq!(c.min_slope(), 1000.0);
        assert_eq!(c.max_slope(), 4000.0);
    }

    #[test]
    fn points_in_compression_are_used_and_energy_is_positive_both_ways() {
        // Four points: soft compression, then two tensile segments.
        let c = PiecewiseLinear::new_material(&[[-0.02, -2.0], [0.0, 0.0], [0.01, 10.0], [0.03, 70.0]]).unwrap();
        assert!((c.value(-0.01) + 1.0).abs() < 1e-12);
        assert!((c.value(-0.04) + 4.0).abs() < 1e-12, "extrapolates below the first point");
        assert!((c.integral(-0.02) - 0.02).abs() < 1e-15);
        assert!(c.integral(-0.03) > c.integral(-0.02));
        assert!((c.integral(0.03) - (0.05 + 0.8)).abs() < 1e-14);
        assert_eq!(c.initial_slope(), 1000.0);
    }

    #[test]
    fn integral_is_the_antiderivative_of_value() {
        let c = PiecewiseLinear::new_material(&[[-0.01, -5.0], [0.0, 0.0], [0.005, 5.0], [0.015, 20.0], [0.035, 98.0]])
            .unwrap();
        let h = 1e-7;
        for i in -60..80 {
            let x = i as f64 * 0.0007 + 0.00013;
            let numeric = (c.integral(x + h) - c.integral(x - h)) / (2.0 * h);
            assert!((numeric - c.value(x)).abs() < 1e-6 * (1.0 + c.value(x).abs()), "at x = {x}");
        }
    }
}
