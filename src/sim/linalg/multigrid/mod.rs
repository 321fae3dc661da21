//! Smoothed-aggregation algebraic multigrid (Vaněk, Mandel and Brezina, 1996) for the
//! Newton matrix, the conjugate gradient's preconditioner where a scene asks for it
//! (`solver.newton.preconditioner = "multigrid"`). A V-cycle's cost grows linearly with
//! the mesh, where a complete factor's fill grows faster; but the CG iterations it leaves
//! grow with the mesh too, and on every drape measured the complete factor is faster, so
//! `auto` does not choose it (docs/solvers.md, Solvers and preconditioners).
//!
//! Each level groups its nodes into aggregates (a node and its strongly coupled
//! neighbours); the coarse space of an aggregate spans its near-null modes, the motions
//! that cost the cloth little energy: three translations and, because a thin sheet bends
//! far more easily than it stretches, three rotations (the rigid motions of a shell). The
//! tentative prolongator is the aggregates' orthonormal bases of those modes (a QR per
//! aggregate, whose R gives the next level its modes); one damped Jacobi sweep smooths it,
//! and the coarse matrix is the Galerkin product PᵀAP. The coarsest level is factored
//! densely. A V-cycle smooths with a Chebyshev polynomial in D⁻¹A, D the node blocks (the
//! same polynomial before and after the coarse correction, so the cycle is symmetric, as CG
//! needs).
//!
//! Written by hand: no crate we can use does smoothed aggregation with geometric
//! near-null modes on our block structure; the sparse products are Gustavson's.

mod csr;
#[cfg(test)]
mod tests;

use crate::sim::linalg::system::SystemMatrix;
use csr::{Csr, scalar_matrix};
use glam::DVec3;
use rayon::prelude::*;

/// Rows per task in the parallel products: below `PARALLEL_ROWS` rows everything runs on
/// the calling thread.
const CHUNK_ROWS: usize = 1024;
const PARALLEL_ROWS: usize = 12_288;

/// Near-null modes per aggregate: three translations, three rotations.
const MODES: usize = 6;

/// A level of this many unknowns or fewer is factored densely.
const COARSEST_UNKNOWNS: usize = 360;

/// Jacobi sweeps that smooth the tentative prolongator: a second sweep leaves as many CG
/// iterations on the fine drapes and makes the build costlier.
const PROLONGATOR_SMOOTHING: usize = 1;

/// At most this many levels (the coarsening stalls long before on meshes).
const MAX_LEVELS: usize = 12;

/// Strength of connection: nodes i and j are coupled strongly when
/// ‖A_ij‖ ≥ θ √(‖A_ii‖ ‖A_jj‖) (Frobenius norms of the blocks). θ = 0 (every one-ring
/// neighbour) leaves more CG iterations on the fine drapes, and θ = 0.25 makes aggregates
/// too small to coarsen.
const STRENGTH: f64 = 0.08;

/// Degree of the Chebyshev smoother, and the share of the largest eigenvalue of D⁻¹A
/// where its interval starts: modes above it are smoothed, those below are left to the
/// coarse levels. Degree 3 leaves fewer CG iterations than degree 2 for a little more work
/// per cycle, and a lower end of 0.05 fewer than 0.1 (the drape's figures are in
/// docs/performance-log.md).
const CHEBYSHEV_DEGREE: usize = 3;
const CHEBYSHEV_LOWER: f64 = 0.05;
const CHEBYSHEV_UPPER: f64 = 1.1;
const POWER_ITERATIONS: usize = 12;

/// Nodes of a level: node i owns unknowns `start[i]..start[i + 1]`.
struct Nodes {
    start: Vec<u32>,
}

impl Nodes {
    fn count(&self) -> usize {
        self.start.len() - 1
    }

    fn unknowns(&self, i: usize) -> std::ops::Range<usize> {
        self.start[i] as usize..self.start[i + 1] as usize
    }

    /// The node of every unknown.
    fn owners(&self) -> Vec<u32> {
        let mut owner = vec![0u32; *self.start.last().expect("non-empty") as usize];
        for i in 0..self.count() {
            owner[self.unknowns(i)].fill(i as u32);
        }
        owner
    }
}

/// Groups the nodes into aggregates (Vaněk, Mandel and Brezina's three passes over the
/// strong-coupling graph): a node whose strong neighbours are all free seeds an aggregate
/// of itself and them; the rest join the aggregate they are most strongly coupled to, and
/// any still left (no aggregated strong neighbour) form aggregates with their free
/// neighbours. `excluded` nodes (fixed vertices) join none. Returns each node's aggregate
/// (u32::MAX for none) and the aggregate count.
fn aggregate(a: &Csr, nodes: &Nodes, excluded: &[bool]) -> (Vec<u32>, usize) {
    let count = nodes.count();
    let owner = nodes.owners();
    // Frobenius norms² of the diagonal blocks, then each node's strong neighbours with
    // their strengths.
    let mut block_norm = vec![0.0f64; count];
    let mut strong: Vec<Vec<(u32, f64)>> = vec![Vec::new(); count];
    let mut sums: Vec<f64> = vec![0.0; count];
    let mut touched: Vec<u32> = Vec::new();
    let row_blocks = |i: usize, touched: &mut Vec<u32>, sums: &mut Vec<f64>| {
        touched.clear();
        for r in nodes.unknowns(i) {
            let (c, v) = a.row(r);
            for (&j, &x) in c.iter().zip(v) {
                let node = owner[j as usize] as usize;
                if sums[node] == 0.0 {
                    touched.push(node as u32);
                }
                sums[node] += x * x;
            }
        }
    };
    for i in 0..count {
        row_blocks(i, &mut touched, &mut sums);
        block_norm[i] = sums[i].sqrt();
        for &j in &touched {
            sums[j as usize] = 0.0;
        }
    }
    for i in 0..count {
        if excluded[i] {
            continue;
        }
        row_blocks(i, &mut touched, &mut sums);
        for &j in &touched {
            let j = j as usize;
            let norm = sums[j].sqrt();
            sums[j] = 0.0;
            if j != i && !excluded[j] && norm >= STRENGTH * (block_norm[i] * block_norm[j]).sqrt() {
                strong[i].push((j as u32, norm));
            }
        }
    }
    const NONE: u32 = u32::MAX;
    let mut of = vec![NONE; count];
    let mut aggregates = 0u32;
    // Pass 1: seeds with every strong neighbour free.
    for i in 0..count {
        if excluded[i] || of[i] != NONE || strong[i].iter().any(|&(j, _)| of[j as usize] != NONE) {
            continue;
        }
        of[i] = aggregates;
        for &(j, _) in &strong[i] {
            of[j as usize] = aggregates;
        }
        aggregates += 1;
    }
    // Pass 2: the rest join their most strongly coupled aggregated neighbour's aggregate
    // (decided on pass 1's aggregates, so the order of the loop does not matter).
    let first = of.clone();
    for i in 0..count {
        if excluded[i] || of[i] != NONE {
            continue;
        }
        let best = strong[i].iter().filter(|&&(j, _)| first[j as usize] != NONE).max_by(|x, y| x.1.total_cmp(&y.1));
        if let Some(&(j, _)) = best {
            of[i] = first[j as usize];
        }
    }
    // Pass 3: nodes with no aggregated strong neighbour (or none at all) seed their own.
    for i in 0..count {
        if excluded[i] || of[i] != NONE {
            continue;
        }
        of[i] = aggregates;
        for &(j, _) in &strong[i] {
            if of[j as usize] == NONE {
                of[j as usize] = aggregates;
            }
        }
        aggregates += 1;
    }
    (of, aggregates as usize)
}

/// The tentative prolongator: for each aggregate an orthonormal basis (Q of a QR by
/// Gram–Schmidt, twice for round-off) of its rows of the near-null modes `modes`
/// (unknowns × MODES, row-major); dependent modes are dropped (an aggregate of one or two
/// vertices, or of collinear ones, spans fewer than six). Returns P, the coarse nodes
/// (one per aggregate, as many unknowns as modes kept) and the coarse level's modes (R).
fn tentative(nodes: &Nodes, of: &[u32], aggregates: usize, modes: &[[f64; MODES]]) -> (Csr, Nodes, Vec<[f64; MODES]>) {
    let unknowns = modes.len();
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); aggregates];
    for (i, &g) in of.iter().enumerate() {
        if g != u32::MAX {
            members[g as usize].extend(nodes.unknowns(i));
        }
    }
    // Each unknown's row of P: (coarse column, value) pairs.
    let mut rows: Vec<Vec<(u32, f64)>> = vec![Vec::new(); unknowns];
    let mut coarse_start = vec![0u32];
    let mut coarse_modes: Vec<[f64; MODES]> = Vec::new();
    for list in &members {
        let m = list.len();
        // Columns of the aggregate's block, Gram–Schmidt in place.
        let mut q: Vec<[f64; MODES]> = list.iter().map(|&u| modes[u]).collect();
        let mut r = [[0.0f64; MODES]; MODES];
        let mut kept: Vec<usize> = Vec::with_capacity(MODES);
        for col in 0..MODES {
            let original = (0..m).map(|i| q[i][col] * q[i][col]).sum::<f64>().sqrt();
            for _ in 0..2 {
                for &prev in &kept {
                    let d: f64 = (0..m).map(|i| q[i][prev] * q[i][col]).sum();
                    r[prev][col] += d;
                    for row in q.iter_mut() {
                        row[col] -= d * row[prev];
                    }
                }
            }
            let norm = (0..m).map(|i| q[i][col] * q[i][col]).sum::<f64>().sqrt();
            if norm > 1e-8 * original && norm > 0.0 {
                r[col][col] = norm;
                for row in q.iter_mut() {
                    row[col] /= norm;
                }
                kept.push(col);
            }
        }
        let base = *coarse_start.last().expect("starts with 0");
        for (i, &u) in list.iter().enumerate() {
            for (k, &col) in kept.iter().enumerate() {
                rows[u].push((base + k as u32, q[i][col]));
            }
        }
        for &col in &kept {
            let mut row = [0.0; MODES];
            row.copy_from_slice(&r[col]);
            coarse_modes.push(row);
        }
        coarse_start.push(base + kept.len() as u32);
    }
    let columns = *coarse_start.last().expect("starts with 0") as usize;
    let mut p = Csr { rows: unknowns, columns, row_start: vec![0], ..Csr::default() };
    for row in rows {
        for (c, v) in row {
            p.cols.push(c);
            p.values.push(v);
        }
        p.row_start.push(p.cols.len() as u32);
    }
    (p, Nodes { start: coarse_start }, coarse_modes)
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// An estimate of the largest eigenvalue of D⁻¹A by power iteration (from a fixed start,
/// so that it is the same on every run), with `inverse` applying D⁻¹.
fn largest_eigenvalue(a: &Csr, inverse: impl Fn(&[f64], &mut [f64])) -> f64 {
    let n = a.rows;
    let mut x: Vec<f64> = (0..n).map(|i| 1.0 + ((i * 7919) % 13) as f64 / 13.0).collect();
    let (mut ax, mut y) = (vec![0.0; n], vec![0.0; n]);
    let mut estimate = 0.0;
    for _ in 0..POWER_ITERATIONS {
        let norm = dot(&x, &x).sqrt();
        x.iter_mut().for_each(|v| *v /= norm);
        a.multiply(&x, &mut ax);
        inverse(&ax, &mut y);
        // Rayleigh quotient in the D inner product: xᵀA x / xᵀD x, with D x from D⁻¹A x
        // and A x (y = D⁻¹A x, so xᵀD y = xᵀA x and yᵀD y = yᵀA x).
        estimate = dot(&y, &ax) / dot(&x, &ax);
        std::mem::swap(&mut x, &mut y);
    }
    estimate
}

/// The inverses of a level's diagonal node blocks (3 × 3 on the finest level, one per
/// vertex; up to 6 × 6 on coarse ones), dense and row-major one after another: the
/// smoother's D. Scalar Jacobi ignores the coupling of an aggregate's translations and
/// rotations, which its blocks hold.
struct BlockDiagonal {
    nodes: Nodes,
    /// Where each node's inverse starts in `inverse`.
    offset: Vec<usize>,
    inverse: Vec<f64>,
    /// The unknowns of every node, where all nodes have as many.
    uniform: Option<usize>,
}

impl BlockDiagonal {
    /// None if a block is not positive definite.
    fn new(a: &Csr, nodes: Nodes) -> Option<Self> {
        let mut offset = Vec::with_capacity(nodes.count() + 1);
        let mut inverse = Vec::new();
        let mut block = Vec::new();
        for i in 0..nodes.count() {
            let range = nodes.unknowns(i);
            let k = range.len();
            offset.push(inverse.len());
            block.clear();
            block.resize(k * k, 0.0);
            for (row, r) in range.clone().enumerate() {
                let (c, v) = a.row(r);
                for (&j, &x) in c.iter().zip(v) {
                    if range.contains(&(j as usize)) {
                        block[row * k + (j as usize - range.start)] = x;
                    }
                }
            }
            if !cholesky(&mut block, k) {
                return None;
            }
            for col in 0..k {
                let mut e = vec![0.0; k];
                e[col] = 1.0;
                cholesky_solve(&block, k, &mut e);
                inverse.extend_from_slice(&e);
            }
        }
        offset.push(inverse.len());
        let first = if nodes.count() > 0 { nodes.unknowns(0).len() } else { 0 };
        let uniform = (0..nodes.count()).all(|i| nodes.unknowns(i).len() == first).then_some(first);
        Some(Self { nodes, offset, inverse, uniform })
    }

    /// out = D⁻¹ r (each inverse is symmetric: stored by columns or rows alike).
    fn apply(&self, r: &[f64], out: &mut [f64]) {
        let node = |i: usize, out: &mut [f64]| {
            let range = self.nodes.unknowns(i);
            let k = range.len();
            let inv = &self.inverse[self.offset[i]..self.offset[i] + k * k];
            for a in 0..k {
                out[a] = (0..k).map(|b| inv[a * k + b] * r[range.start + b]).sum();
            }
        };
        // The finest level's nodes are all vertices of three unknowns: chunks of them run on
        // rayon's pool when the level is large.
        if let Some(k) = self.uniform
            && out.len() >= PARALLEL_ROWS
        {
            out.par_chunks_mut(k * CHUNK_ROWS).enumerate().for_each(|(c, chunk)| {
                for (j, node_out) in chunk.chunks_mut(k).enumerate() {
                    node(c * CHUNK_ROWS + j, node_out);
                }
            });
            return;
        }
        for i in 0..self.nodes.count() {
            let range = self.nodes.unknowns(i);
            node(i, &mut out[range]);
        }
    }
}

/// One level of the hierarchy (all but the coarsest).
struct Level {
    a: Csr,
    smoother: BlockDiagonal,
    /// Largest eigenvalue of D⁻¹A (raised by `CHEBYSHEV_UPPER`).
    lambda: f64,
    /// Prolongator from the next level, and its transpose.
    p: Csr,
    restriction: Csr,
}

impl Level {
    /// x += S(b − A x) with the Chebyshev polynomial S; `x_zero`: x is zero on entry
    /// (saves the first product).
    fn smooth(&self, b: &[f64], x: &mut [f64], x_zero: bool, work: &mut [Vec<f64>; 2]) {
        let [r, d] = work;
        let n = b.len();
        if x_zero {
            r.copy_from_slice(b);
        } else {
            self.a.multiply(x, r);
            for i in 0..n {
                r[i] = b[i] - r[i];
            }
        }
        let (upper, lower) = (self.lambda, CHEBYSHEV_LOWER * self.lambda);
        let theta = 0.5 * (upper + lower);
        let delta = 0.5 * (upper - lower);
        let sigma = theta / delta;
        let mut rho = 1.0 / sigma;
        let mut z = vec![0.0; n];
        self.smoother.apply(r, &mut z);
        for i in 0..n {
            d[i] = z[i] / theta;
        }
        let mut ad = vec![0.0; n];
        for k in 0..CHEBYSHEV_DEGREE {
            for i in 0..n {
                x[i] += d[i];
            }
            if k + 1 == CHEBYSHEV_DEGREE {
                break;
            }
            self.a.multiply(d, &mut ad);
            let rho_next = 1.0 / (2.0 * sigma - rho);
            for i in 0..n {
                r[i] -= ad[i];
            }
            self.smoother.apply(r, &mut z);
            for i in 0..n {
                d[i] = rho_next * rho * d[i] + 2.0 * rho_next / delta * z[i];
            }
            rho = rho_next;
        }
    }
}

/// The hierarchy: levels from the finest down, and the coarsest matrix's dense Cholesky
/// factor.
pub struct Multigrid {
    levels: Vec<Level>,
    /// Lower-triangular factor of the coarsest matrix, row-major (size × size).
    coarse: Vec<f64>,
    coarse_size: usize,
    /// Estimated cost of the build in conjugate-gradient iterations with it (see
    /// `SETUP_SPEED_RATIO`).
    pub cost_in_iterations: f64,
    /// Unknowns on each level, finest first (the coarsest last).
    pub sizes: Vec<usize>,
}

/// A build's time over what its multiply-add count says in CG iterations: a multiply-add
/// in the sparse products' scattered accumulation and the per-aggregate work costs more
/// than one in a streamed product (the ratio was timed on a fine drape;
/// docs/performance-log.md). The cost stays a count, so that the rent-or-buy choice is the
/// same on every machine.
const SETUP_SPEED_RATIO: f64 = 3.5;

impl Multigrid {
    /// Builds the hierarchy for `a` with the rigid modes of the cloth at `positions`; None
    /// if the matrix is not positive definite where it shows (a non-positive diagonal, or
    /// a coarsest matrix that cannot be factored).
    pub fn new(a: &SystemMatrix, positions: &[DVec3]) -> Option<Self> {
        let n = a.fixed.len();
        let fine = scalar_matrix(a, true);
        // On the finest level, aggregates and the prolongator's smoothing see the in-plane
        // one-ring only (the filtered matrix of smoothed aggregation): the bending stencil
        // is two rings wide, and with it the aggregates, the prolongator's rows and the
        // Galerkin products grow several times over, for a few CG iterations fewer.
        // Keeping the bending entries within the one-ring and lumping the rest into the
        // diagonal would save more, but the lumped diagonal is negative on irregular
        // meshes (the fitted stencils' one-ring entries need not be negative).
        let mut filtered = Some(scalar_matrix(a, false));
        // Translations and rotations about each vertex's own aggregate would be better
        // conditioned; about the centroid of the cloth they span the same space, and the
        // QR per aggregate removes the offset.
        let centre = positions.iter().copied().sum::<DVec3>() / n.max(1) as f64;
        let mut modes = vec![[0.0; MODES]; 3 * n];
        for v in 0..n {
            if a.fixed[v] {
                continue;
            }
            let r = positions[v] - centre;
            // Rotation ω gives the displacement ω × r.
            let rotation = [[0.0, r.z, -r.y], [-r.z, 0.0, r.x], [r.y, -r.x, 0.0]];
            for c in 0..3 {
                let mut row = [0.0; MODES];
                row[c] = 1.0;
                row[3..].copy_from_slice(&rotation[c]);
                modes[3 * v + c] = row;
            }
        }
        let mut nodes = Nodes { start: (0..=n as u32).map(|v| 3 * v).collect() };
        let mut excluded: Vec<bool> = a.fixed.to_vec();
        let mut matrix = fine;
        let mut levels = Vec::new();
        let mut setup_flops = 0.0;
        let mut cycle_flops = 0.0;
        let mut sizes = Vec::new();
        while matrix.rows > COARSEST_UNKNOWNS && levels.len() < MAX_LEVELS {
            // (A block that is not positive definite, a non-positive diagonal entry included,
            // fails here.)
            let smoother = BlockDiagonal::new(&matrix, Nodes { start: nodes.start.clone() })?;
            let lambda = CHEBYSHEV_UPPER * largest_eigenvalue(&matrix, |r, out| smoother.apply(r, out));
            // The prolongator is smoothed with scalar Jacobi, D the diagonal.
            let coarsening = filtered.take();
            let coarsening = coarsening.as_ref().unwrap_or(&matrix);
            let coarsening_diagonal = coarsening.diagonal();
            if !coarsening_diagonal.iter().all(|&d| d > 0.0) {
                return None;
            }
            let coarsening_inverse_diagonal: Vec<f64> = coarsening_diagonal.iter().map(|d| 1.0 / d).collect();
            let scalar_inverse = |r: &[f64], out: &mut [f64]| {
                for ((o, x), d) in out.iter_mut().zip(r).zip(&coarsening_inverse_diagonal) {
                    *o = x * d;
                }
            };
            let coarsening_lambda = largest_eigenvalue(coarsening, scalar_inverse);
            let (of, count) = aggregate(coarsening, &nodes, &excluded);
            let (tentative, coarse_nodes, coarse_modes) = tentative(&nodes, &of, count, &modes);
            if tentative.columns == 0 || tentative.columns as f64 > 0.8 * matrix.rows as f64 {
                break;
            }
            // P = (I − ω D⁻¹A)^s P_t, ω = 4/(3ρ(D⁻¹A)).
            let omega = 4.0 / (3.0 * coarsening_lambda);
            let mut p = tentative;
            for _ in 0..PROLONGATOR_SMOOTHING {
                let (mut next, flops) = coarsening.product(&p);
                setup_flops += flops;
                for (i, &inverse) in coarsening_inverse_diagonal.iter().enumerate() {
                    let (s, e) = (next.row_start[i] as usize, next.row_start[i + 1] as usize);
                    let (pc, pv) = p.row(i);
                    for k in s..e {
                        // Both rows are sorted; P's pattern is within (I + A)P's.
                        let old = pc.binary_search(&next.cols[k]).map_or(0.0, |j| pv[j]);
                        next.values[k] = old - omega * inverse * next.values[k];
                    }
                }
                p = next;
            }
            let restriction = p.transpose();
            let (ap, flops_ap) = matrix.product(&p);
            let (coarse, flops_c) = restriction.product(&ap);
            setup_flops += flops_ap + flops_c;
            cycle_flops += (2 * CHEBYSHEV_DEGREE + 1) as f64 * matrix.entries() as f64 + 2.0 * p.entries() as f64;
            sizes.push(matrix.rows);
            levels.push(Level { a: matrix, smoother, lambda, p, restriction });
            excluded = vec![false; coarse_nodes.count()];
            nodes = coarse_nodes;
            modes = coarse_modes;
            matrix = coarse;
        }
        let size = matrix.rows;
        sizes.push(size);
        let mut dense = vec![0.0; size * size];
        for i in 0..size {
            let (c, v) = matrix.row(i);
            for (&j, &x) in c.iter().zip(v) {
                dense[i * size + j as usize] = x;
            }
        }
        // An unknown with an empty row (a dropped mode makes none, so none is expected)
        // would make the factor fail: the identity there.
        for i in 0..size {
            if dense[i * size + i] == 0.0 && (0..size).all(|j| dense[i * size + j] == 0.0) {
                dense[i * size + i] = 1.0;
            }
        }
        let coarse = cholesky(&mut dense, size).then_some(dense)?;
        setup_flops += (size * size * size) as f64 / 6.0;
        cycle_flops += 2.0 * (size * size) as f64;
        let apply_flops = cycle_flops + levels.first().map_or(0.0, |l| l.a.entries() as f64);
        let cost_in_iterations = SETUP_SPEED_RATIO * setup_flops / apply_flops.max(1.0);
        Some(Self { levels, coarse, coarse_size: size, cost_in_iterations, sizes })
    }

    /// z ≈ A⁻¹ r by one V-cycle from zero.
    pub fn solve(&self, r: &[DVec3], z: &mut [DVec3]) {
        let b: Vec<f64> = r.iter().flat_map(|v| v.to_array()).collect();
        let mut x = vec![0.0; b.len()];
        self.cycle(0, &b, &mut x);
        for (i, out) in z.iter_mut().enumerate() {
            *out = DVec3::new(x[3 * i], x[3 * i + 1], x[3 * i + 2]);
        }
    }

    fn cycle(&self, level: usize, b: &[f64], x: &mut [f64]) {
        let Some(this) = self.levels.get(level) else {
            x.copy_from_slice(b);
            cholesky_solve(&self.coarse, self.coarse_size, x);
            return;
        };
        let n = b.len();
        let mut work = [vec![0.0; n], vec![0.0; n]];
        this.smooth(b, x, true, &mut work);
        let residual = &mut work[0];
        this.a.multiply(x, residual);
        for i in 0..n {
            residual[i] = b[i] - residual[i];
        }
        let mut coarse_b = vec![0.0; this.p.columns];
        this.restriction.multiply(residual, &mut coarse_b);
        let mut coarse_x = vec![0.0; this.p.columns];
        self.cycle(level + 1, &coarse_b, &mut coarse_x);
        let correction = &mut work[1];
        this.p.multiply(&coarse_x, correction);
        for i in 0..n {
            x[i] += correction[i];
        }
        this.smooth(b, x, false, &mut work);
    }
}

/// Dense Cholesky in place (row-major, lower triangle); false if a pivot is not positive.
fn cholesky(a: &mut [f64], n: usize) -> bool {
    for j in 0..n {
        let mut d = a[j * n + j];
        for k in 0..j {
            d -= a[j * n + k] * a[j * n + k];
        }
        // (NaN fails too.)
        if d.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return false;
        }
        let d = d.sqrt();
        a[j * n + j] = d;
        for i in j + 1..n {
            let mut s = a[i * n + j];
            for k in 0..j {
                s -= a[i * n + k] * a[j * n + k];
            }
            a[i * n + j] = s / d;
        }
    }
    true
}

/// Solves L Lᵀ x = b in place with the factor from `cholesky`.
fn cholesky_solve(l: &[f64], n: usize, x: &mut [f64]) {
    for i in 0..n {
        let s: f64 = (0..i).map(|k| l[i * n + k] * x[k]).sum();
        x[i] = (x[i] - s) / l[i * n + i];
    }
    for i in (0..n).rev() {
        let s: f64 = (i + 1..n).map(|k| l[k * n + i] * x[k]).sum();
        x[i] = (x[i] - s) / l[i * n + i];
    }
}

