//! Tensile curves from the laboratories' summary numbers.
//!
//! KES-FB1 reports three numbers for a pull to Fm: the strain EMT at Fm, the energy WT
//! under the curve and its linearity LT = WT / (Fm·EMT/2) (docs/references.md §8). A
//! curve with LT < 1 stiffens; the simplest one that meets all three exactly has two
//! segments, and the knee's position along the line that fixes the area is free. We put
//! the knee on the anti-diagonal of the (ε/EMT, F/Fm) box:
//!
//! ```text
//!   F/Fm
//!    1 ┤                  ●   end point (EMT, Fm)
//!      │                 /
//!      │               /      second slope (1 − LT/2)/(LT/2) · Fm/EMT
//! LT/2 ┤      ___---●         knee (1 − LT/2, LT/2)
//!      │___---              first slope (LT/2)/(1 − LT/2) · Fm/EMT
//!    0 ●─────────────┬────┬─ ε/EMT
//!                 1 − LT/2  1
//! ```
//!
//! The area under it is ½[(1 − LT/2)·LT/2 + (LT/2 + 1)·LT/2] = LT/2 in these units, i.e.
//! WT = LT·Fm·EMT/2 exactly; the end point is (EMT, Fm); LT = 1 is the straight line. The
//! anti-diagonal is the choice symmetric under swapping the roles of load and strain, so
//! the curve favours neither a long soft toe nor a short one; a fabric's real toe is not
//! in the three numbers.
//!
//! FAST-3 reports the strain at three loads, 5, 20 and 100 gf/cm: the curve goes through
//! those points and the origin.

use super::units::GF_PER_CM;

/// The two-segment KES curve through the origin with strain `emt` (a fraction) at load
/// `fm` (N/m) and linearity `lt` in (0, 1]: `[[strain, N/m], ...]`.
pub fn kes_curve(emt: f64, lt: f64, fm: f64) -> Vec<[f64; 2]> {
    assert!(emt > 0.0 && fm > 0.0 && lt > 0.0 && lt <= 1.0, "checked by the caller: EMT {emt}, LT {lt}, Fm {fm}");
    if lt >= 1.0 - 1e-12 {
        return vec![[0.0, 0.0], [emt, fm]];
    }
    let knee = [(1.0 - 0.5 * lt) * emt, 0.5 * lt * fm];
    vec![[0.0, 0.0], knee, [emt, fm]]
}

/// The area under a piecewise-linear curve from the origin to its last point, N/m
/// (J/m²): the tensile energy WT.
pub fn energy(curve: &[[f64; 2]]) -> f64 {
    curve.windows(2).map(|w| 0.5 * (w[0][1] + w[1][1]) * (w[1][0] - w[0][0])).sum()
}

/// FAST-3's loads, N/m: 5, 20 and 100 gf/cm.
pub const FAST_LOADS: [f64; 3] = [5.0 * GF_PER_CM, 20.0 * GF_PER_CM, 100.0 * GF_PER_CM];

/// The FAST curve through the origin and (E5, 5 gf/cm), (E20, 20 gf/cm), (E100, 100 gf/cm),
/// strains as fractions; a missing strain (None) leaves its point out. None if the strains
/// given do not increase with the load.
pub fn fast_curve(strains: [Option<f64>; 3]) -> Option<Vec<[f64; 2]>> {
    let mut curve = vec![[0.0, 0.0]];
    for (strain, load) in strains.iter().zip(FAST_LOADS) {
        if let Some(e) = *strain {
            if e <= curve.last().expect("starts with the origin")[0] {
                return None;
            }
            curve.push([e, load]);
        }
    }
    (curve.len() >= 2).then_some(curve)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kes_curve_meets_emt_wt_and_lt_exactly() {
        let fm = 500.0 * GF_PER_CM;
        for (emt, lt) in [(0.05, 0.6), (0.03, 0.9), (0.12, 0.45), (0.04, 1.0)] {
            let curve = kes_curve(emt, lt, fm);
            let last = curve.last().unwrap();
            assert_eq!(*last, [emt, fm]);
            let wt = energy(&curve);
            assert!((wt - lt * fm * emt / 2.0).abs() < 1e-12 * wt, "WT = LT·Fm·EMT/2");
            // Stiffening: every segment at least as steep as the one before.
            let slopes: Vec<f64> = curve.windows(2).map(|w| (w[1][1] - w[0][1]) / (w[1][0] - w[0][0])).collect();
            assert!(slopes.windows(2).all(|s| s[1] >= s[0]), "{slopes:?}");
        }
    }

    #[test]
    fn fast_curve_passes_through_the_three_loads() {
        let curve = fast_curve([Some(0.0067), Some(0.0187), Some(0.046)]).unwrap();
        assert_eq!(curve.len(), 4);
        assert!((curve[3][1] - 98.0665).abs() < 1e-9);
        assert!(fast_curve([Some(0.02), Some(0.01), Some(0.05)]).is_none(), "strains must grow with the load");
        assert_eq!(fast_curve([None, None, Some(0.05)]).unwrap().len(), 2);
    }
}
