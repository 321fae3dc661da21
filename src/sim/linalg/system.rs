//! The Newton system matrix: inertia, the in-plane blocks, bending and contact couplings.

use super::storage::{BlockCsr, ScalarCsr, for_row_groups, for_rows};
use glam::{DMat3, DVec3};

/// The Newton system matrix `A = diag(mass_diagonal) + K + Q ⊗ I₃`, with fixed vertices removed.
pub struct SystemMatrix<'a> {
    pub mass_diagonal: &'a [f64],
    pub stiffness: &'a BlockCsr,
    pub bending: Option<&'a ScalarCsr>,
    /// `true` for vertices whose positions are prescribed (their rows and columns are dropped).
    pub fixed: &'a [bool],
    /// Rank-one couplings k·g gᵀ between a few vertices (cloth–cloth contact), whose
    /// diagonal blocks are already in `stiffness`: only their off-diagonal part is applied.
    pub couplings: &'a [Coupling],
}

/// A rank-one term k·g gᵀ of the system matrix with g = (c₀n, c₁n, c₂n, c₃n) on four
/// vertices: the Gauss–Newton Hessian of a penalty on one distance.
#[derive(Debug, Clone, Copy)]
pub struct Coupling {
    pub vertices: [u32; 4],
    pub weights: [f64; 4],
    pub normal: DVec3,
    pub stiffness: f64,
}

impl SystemMatrix<'_> {
    pub(super) fn apply(&self, x: &[DVec3], y: &mut [DVec3]) {
        // One pass over the rows for the three terms: separate passes would read and
        // write y three times, and the product is bound by memory traffic.
        for_rows(y, |row, out| {
            *out = if self.fixed[row] {
                DVec3::ZERO
            } else {
                let bending = self.bending.map_or(DVec3::ZERO, |q| q.row_product(row, x));
                self.stiffness.row_product(row, x) + bending + self.mass_diagonal[row] * x[row]
            };
        });
        self.apply_couplings(x, y, 1);
    }

    /// Y = A X for the `k` vectors of `x` stored side by side (`x[row * k + j]` is row
    /// `row` of the `j`-th), reading the matrix once for all of them: k products at
    /// little more than the memory traffic of one.
    pub(super) fn apply_many(&self, k: usize, x: &[DVec3], y: &mut [DVec3]) {
        for_row_groups(y, k, |row, out| {
            out.fill(DVec3::ZERO);
            if self.fixed[row] {
                return;
            }
            self.stiffness.row_product_add_many(row, x, out);
            if let Some(q) = self.bending {
                q.row_product_add_many(row, x, out);
            }
            for (o, v) in out.iter_mut().zip(&x[row * k..row * k + k]) {
                *o += self.mass_diagonal[row] * *v;
            }
        });
        self.apply_couplings(x, y, k);
    }

    /// The couplings' off-diagonal part added to `y`, for `k` vectors side by side.
    fn apply_couplings(&self, x: &[DVec3], y: &mut [DVec3], k: usize) {
        for c in self.couplings {
            for vector in 0..k {
                let at = |j: usize| c.vertices[j] as usize * k + vector;
                let along = |j: usize| c.weights[j] * c.normal.dot(x[at(j)]);
                let total: f64 = (0..4).map(along).sum();
                for j in 0..4 {
                    if !self.fixed[c.vertices[j] as usize] {
                        y[at(j)] += c.stiffness * c.weights[j] * (total - along(j)) * c.normal;
                    }
                }
            }
        }
    }

    /// Inverse 3×3 diagonal blocks: the block-Jacobi preconditioner.
    pub(crate) fn block_jacobi(&self) -> Vec<DMat3> {
        (0..self.fixed.len())
            .map(|i| {
                if self.fixed[i] {
                    return DMat3::ZERO;
                }
                let q = self.bending.map_or(0.0, |q| q.diagonal(i as u32));
                let block = self.stiffness.values[self.stiffness.diagonal_slot(i as u32)]
                    + DMat3::from_diagonal(DVec3::splat(self.mass_diagonal[i] + q));
                block.inverse()
            })
            .collect()
    }
}

