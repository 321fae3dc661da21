//! faer's supernodal Cholesky factor, factored and solved with on two threads.
//!
//! faer's own numeric factorisation and solves walk the supernodes one after another, and
//! on the fine drapes they are what a run waits for: a solve reads the whole factor twice,
//! and the factor grows faster than the mesh. faer's rayon mode parallelises the dense work
//! inside each supernode, and on these small supernodes it was slower (see
//! `direct::PARALLELISM`). Here the elimination tree is cut
//! instead: two groups of disjoint subtrees, of about equal size, are worked at once, one
//! per thread, and the few supernodes above both (the last separators) after them
//! (factorisation, forward substitution) or before them (back substitution).
//!
//! The factorisation is faer's left-looking one, with faer's dense kernels: a supernode
//! pulls the updates of the supernodes below it, which are in its own subtree, so each
//! group reads and writes only its own supernodes. The triangular solves' kernels are
//! written out, column by column over each supernode's dense trapezoid. Both threads run
//! the same code as one thread does, on the same groups: the results are the same whatever
//! the number of threads.

use faer::sparse::linalg::cholesky::{SymbolicCholesky, SymbolicCholeskyRaw};

/// One supernode: columns `start..start + size` of L, stored as a dense column-major
/// block of `size + pattern.len()` rows from `values`; the rows below its diagonal block
/// are `pattern`.
#[derive(Debug, Clone, Copy)]
struct Supernode {
    start: u32,
    size: u32,
    values: usize,
    pattern_start: u32,
    pattern_len: u32,
}

/// The layout of a supernodal factor and the split of its supernodes between two threads.
#[derive(Debug)]
pub struct SupernodalPlan {
    nodes: Vec<Supernode>,
    /// Every supernode's below-diagonal rows, one after another.
    rows: Vec<u32>,
    /// The fill-reducing permutation: row i of the factor is row `forward[i]` of the matrix.
    forward: Vec<u32>,
    /// The supernodes of each thread's subtrees, ascending (children before parents).
    groups: [Vec<u32>; 2],
    /// The supernodes above both groups, ascending.
    top: Vec<u32>,
    /// Which of `groups` owns each row of the factor, or `TOP`.
    owner: Vec<u8>,
    /// Entries of L.
    len: usize,
    /// From this many entries of L on, the groups run on two threads.
    parallel_entries: usize,
    /// The supernode of each column.
    column_node: Vec<u32>,
    /// For each supernode, the earlier supernodes whose rows reach into its columns (the
    /// updates a left-looking factorisation pulls in), ascending.
    updaters: Vec<Vec<u32>>,
}

/// The owner of a row in no group.
const TOP: u8 = 2;

/// Below this many entries of L a solve takes about a millisecond or less, and the two
/// groups run on the calling thread (the same arithmetic, so the same result).
const PARALLEL_ENTRIES: usize = 1 << 20;

impl SupernodalPlan {
    /// The plan for `symbolic`'s factor; None if faer chose a simplicial factor.
    pub fn new(symbolic: &SymbolicCholesky<u32>) -> Option<Self> {
        let SymbolicCholeskyRaw::Supernodal(s) = symbolic.raw() else { return None };
        let count = s.n_supernodes();
        let (begin, end) = (s.supernode_begin(), s.supernode_end());
        let nodes: Vec<Supernode> = (0..count)
            .map(|k| Supernode {
                start: begin[k],
                size: end[k] - begin[k],
                values: s.col_ptr_for_val()[k] as usize,
                pattern_start: s.col_ptr_for_row_idx()[k],
                pattern_len: s.nnz_per_super()[k],
            })
            .collect();
        let dimension = s.nrows();
        let forward: Vec<u32> = match symbolic.perm() {
            Some(p) => p.arrays().0.to_vec(),
            None => (0..dimension as u32).collect(),
        };
        let rows = s.row_idx().to_vec();
        let mut column_node = vec![0u32; dimension];
        for (k, n) in nodes.iter().enumerate() {
            column_node[n.start as usize..(n.start + n.size) as usize].fill(k as u32);
        }
        // The supernodal elimination tree: a supernode's parent holds its first row below
        // the diagonal block (every later one belongs to an ancestor).
        let parent: Vec<Option<u32>> = nodes
            .iter()
            .map(|n| (n.pattern_len > 0).then(|| column_node[rows[n.pattern_start as usize] as usize]))
            .collect();
        let mut children = vec![Vec::new(); count];
        let mut roots = Vec::new();
        for (k, p) in parent.iter().enumerate() {
            match p {
                Some(p) => children[*p as usize].push(k as u32),
                None => roots.push(k as u32),
            }
        }
        let entries = |n: &Supernode| (n.size as usize + n.pattern_len as usize) * n.size as usize;
        // Subtree sizes, children first (a parent comes after its children).
        let mut subtree: Vec<usize> = nodes.iter().map(entries).collect();
        for k in 0..count {
            if let Some(p) = parent[k] {
                subtree[p as usize] += subtree[k];
            }
        }
        let total: usize = subtree.iter().zip(&parent).filter(|(_, p)| p.is_none()).map(|(w, _)| w).sum();
        // Split the largest subtree (its root goes on top), deal the subtrees to the two
        // groups largest first, and keep the split whose time on two threads, the top's
        // entries plus the larger group's, is least. A balanced split can cost more than a
        // slightly unbalanced one with fewer supernodes on top, which run alone.
        let mut candidates = roots;
        let mut top_entries = 0;
        let mut best: Option<(usize, [Vec<u32>; 2])> = None;
        while !candidates.is_empty() && 2 * top_entries < total {
            candidates.sort_by_key(|&k| std::cmp::Reverse(subtree[k as usize]));
            let mut load = [0usize; 2];
            let mut assignment = [Vec::new(), Vec::new()];
            for &k in &candidates {
                let g = if load[0] <= load[1] { 0 } else { 1 };
                load[g] += subtree[k as usize];
                assignment[g].push(k);
            }
            let time = top_entries + load[0].max(load[1]);
            if best.as_ref().is_none_or(|(t, _)| time < *t) {
                best = Some((time, assignment));
            }
            let largest = candidates.remove(0);
            top_entries += entries(&nodes[largest as usize]);
            candidates.extend_from_slice(&children[largest as usize]);
        }
        let assignment = best.map_or_else(|| [Vec::new(), Vec::new()], |(_, a)| a);
        let mut owner_of_node = vec![TOP; count];
        for (g, subtree_roots) in assignment.iter().enumerate() {
            let mut stack = subtree_roots.clone();
            while let Some(k) = stack.pop() {
                owner_of_node[k as usize] = g as u8;
                stack.extend_from_slice(&children[k as usize]);
            }
        }
        let members = |g: u8| (0..count as u32).filter(|&k| owner_of_node[k as usize] == g).collect::<Vec<u32>>();
        let owner: Vec<u8> = column_node.iter().map(|&k| owner_of_node[k as usize]).collect();
        let mut updaters = vec![Vec::new(); count];
        for (d, n) in nodes.iter().enumerate() {
            let pattern = &rows[n.pattern_start as usize..(n.pattern_start + n.pattern_len) as usize];
            let mut last = u32::MAX;
            for &r in pattern {
                let t = column_node[r as usize];
                if t != last {
                    updaters[t as usize].push(d as u32);
                    last = t;
                }
            }
        }
        Some(Self {
            groups: [members(0), members(1)],
            top: members(TOP),
            nodes,
            rows,
            forward,
            owner,
            len: s.len_val(),
            parallel_entries: PARALLEL_ENTRIES,
            column_node,
            updaters,
        })
    }

    /// Share of L's entries in the supernodes above the two groups, and the difference
    /// between the groups', of the whole.
    #[cfg(test)]
    fn split(&self) -> (f64, f64) {
        let entries = |list: &[u32]| -> usize { list.iter().map(|&k| self.node_entries(k)).sum() };
        let total = self.len.max(1) as f64;
        let (a, b) = (entries(&self.groups[0]), entries(&self.groups[1]));
        (entries(&self.top) as f64 / total, a.abs_diff(b) as f64 / total)
    }

    #[cfg(test)]
    fn node_entries(&self, k: u32) -> usize {
        let n = &self.nodes[k as usize];
        (n.size as usize + n.pattern_len as usize) * n.size as usize
    }

    /// x = (LLᵀ)⁻¹ b for the factor `values`, b given and x returned in the matrix's order
    /// (`get(i)` is b_i; `set(i, x_i)` receives the solution).
    pub fn solve(&self, values: &[f32], get: impl Fn(usize) -> f32, mut set: impl FnMut(usize, f32)) {
        assert_eq!(values.len(), self.len, "a factor of another pattern");
        let mut x: Vec<f32> = self.forward.iter().map(|&i| get(i as usize)).collect();
        self.lower_solve(values, &mut x);
        self.upper_solve(values, &mut x);
        for (&i, &xi) in self.forward.iter().zip(&x) {
            set(i as usize, xi);
        }
    }

    /// Where each entry of a matrix's lower triangle goes in L: entry k of column c, row
    /// `row_idx[k]`, of the matrix whose columns start at `col_ptr` (the symmetric
    /// permutation moves it to row and column `inverse`).
    pub fn destinations(&self, col_ptr: &[u32], row_idx: &[u32]) -> Vec<usize> {
        let mut inverse = vec![0u32; self.forward.len()];
        for (i, &f) in self.forward.iter().enumerate() {
            inverse[f as usize] = i as u32;
        }
        let mut out = Vec::with_capacity(row_idx.len());
        for c in 0..col_ptr.len() - 1 {
            for &r in &row_idx[col_ptr[c] as usize..col_ptr[c + 1] as usize] {
                let (a, b) = (inverse[r as usize], inverse[c]);
                let (i, j) = (a.max(b), a.min(b));
                let node = self.column_node[j as usize];
                let n = self.nodes[node as usize];
                let rows = (n.size + n.pattern_len) as usize;
                let position = if i < n.start + n.size {
                    (i - n.start) as usize
                } else {
                    let pattern = &self.rows[n.pattern_start as usize..(n.pattern_start + n.pattern_len) as usize];
                    n.size as usize + pattern.binary_search(&i).expect("the symbolic factor's pattern holds every entry")
                };
                out.push(n.values + (j - n.start) as usize * rows + position);
            }
        }
        out
    }

    /// Factors the matrix whose lower-triangle entries are `entries`, placed by
    /// `destinations`, into `l`; false if it is not positive definite. faer's left-looking
    /// supernodal LLᵀ, but with the two groups' subtrees factored at once: a supernode
    /// pulls updates from earlier supernodes of its own subtree only, so each group reads
    /// and writes its own supernodes, and the top ones follow.
    pub fn factor(&self, entries: &[f32], destinations: &[usize], l: &mut [f32]) -> bool {
        assert_eq!(l.len(), self.len, "a factor of another pattern");
        l.fill(0.0);
        for (&value, &d) in entries.iter().zip(destinations) {
            l[d] += value;
        }
        let shared = SharedFactor(l.as_mut_ptr());
        let largest = self.nodes.iter().map(|n| n.size as usize).max().unwrap_or(0);
        let run = |nodes: &[u32]| {
            let mut scratch = NodeScratch::new(self.column_node.len(), largest);
            // SAFETY: the supernodes of a group write only their own blocks and read only
            // blocks of the supernodes below them, which are in the same group's subtrees;
            // the two groups share no supernode, and the top ones run after both.
            nodes.iter().all(|&k| unsafe { self.factor_node(&shared, k, &mut scratch) })
        };
        let [first, second] = &self.groups;
        let (a, b) = if self.len >= self.parallel_entries && rayon::current_num_threads() > 1 {
            rayon::join(|| run(first), || run(second))
        } else {
            (run(first), run(second))
        };
        a && b && run(&self.top)
    }

    /// Factors supernode k of the factor behind `shared`, whose descendants are done.
    ///
    /// # Safety
    /// No other thread may be writing supernode k or reading or writing any of the
    /// supernodes it pulls updates from.
    unsafe fn factor_node(&self, shared: &SharedFactor, k: u32, scratch: &mut NodeScratch) -> bool {
        use faer::linalg::matmul::triangular::BlockStructure;
        use faer::reborrow::{Reborrow, ReborrowMut};
        use faer::{Accum, MatMut, MatRef, Par};
        let n = self.nodes[k as usize];
        let (start, size) = (n.start as usize, n.size as usize);
        let end = start + size;
        let pattern = &self.rows[n.pattern_start as usize..(n.pattern_start + n.pattern_len) as usize];
        let rows = size + pattern.len();
        for (i, &r) in pattern.iter().enumerate() {
            scratch.local[r as usize] = (size + i) as u32;
        }
        // SAFETY: by the caller's promise this block is ours alone.
        let own = unsafe { std::slice::from_raw_parts_mut(shared.0.add(n.values), rows * size) };
        let mut ls = MatMut::from_column_major_slice_mut(own, rows, size);
        for &d in &self.updaters[k as usize] {
            let m = self.nodes[d as usize];
            let d_rows = (m.size + m.pattern_len) as usize;
            // SAFETY: supernode d is finished and nobody writes it.
            let block = unsafe { std::slice::from_raw_parts(shared.0.add(m.values), d_rows * m.size as usize) };
            let ld = MatRef::from_column_major_slice(block, d_rows, m.size as usize);
            let d_pattern = &self.rows[m.pattern_start as usize..(m.pattern_start + m.pattern_len) as usize];
            let first = d_pattern.partition_point(|&r| (r as usize) < start);
            let mid = d_pattern[first..].partition_point(|&r| (r as usize) < end);
            let below = ld.subrows(m.size as usize + first, d_pattern.len() - first);
            let upper = below.subrows(0, mid);
            // The update L_below · L_upperᵀ: its top square's lower triangle and the rest.
            let height = below.nrows();
            scratch.product.clear();
            scratch.product.resize(height * mid, 0.0);
            let mut product = MatMut::from_column_major_slice_mut(&mut scratch.product, height, mid);
            let (top, rest) = product.rb_mut().split_at_row_mut(mid);
            faer::linalg::matmul::triangular::matmul(
                top,
                BlockStructure::TriangularLower,
                Accum::Replace,
                upper,
                BlockStructure::Rectangular,
                upper.transpose(),
                BlockStructure::Rectangular,
                1.0f32,
                Par::Seq,
            );
            faer::linalg::matmul::matmul(rest, Accum::Replace, below.subrows(mid, height - mid), upper.transpose(), 1.0f32, Par::Seq);
            let target_row = |i: usize| {
                let r = d_pattern[first + i] as usize;
                if i < mid { r - start } else { scratch.local[r] as usize }
            };
            let positions = &mut scratch.positions;
            positions.clear();
            positions.extend((0..height).map(target_row));
            for j in 0..mid {
                let column = positions[j];
                for i in j..height {
                    ls[(positions[i], column)] -= product[(i, j)];
                }
            }
        }
        for &r in pattern {
            scratch.local[r as usize] = u32::MAX;
        }
        let (mut top, bottom) = ls.split_at_row_mut(size);
        let stack = faer::dyn_stack::MemStack::new(&mut scratch.stack);
        if faer::linalg::cholesky::llt::factor::cholesky_in_place(top.rb_mut(), Default::default(), Par::Seq, stack, Default::default()).is_err() {
            return false;
        }
        faer::linalg::triangular_solve::solve_lower_triangular_in_place(top.rb(), bottom.transpose_mut(), Par::Seq);
        true
    }

    /// Both groups at once on copies of x; `merge` takes each group's result back.
    fn on_both_groups(&self, x: &[f32], run: impl Fn(&[u32], &mut [f32]) + Sync) -> [Vec<f32>; 2] {
        let (mut a, mut b) = (x.to_vec(), x.to_vec());
        let ([first, second], (run_a, run_b)) = (&self.groups, (&run, &run));
        if self.len >= self.parallel_entries && rayon::current_num_threads() > 1 {
            rayon::join(|| run_a(first, &mut a), || run_b(second, &mut b));
        } else {
            run_a(first, &mut a);
            run_b(second, &mut b);
        }
        [a, b]
    }

    /// x ← L⁻¹x (x in the factor's order).
    fn lower_solve(&self, values: &[f32], x: &mut [f32]) {
        let [a, b] = self.on_both_groups(x, |nodes, y| self.lower_nodes(values, nodes.iter().copied(), y));
        // A group changes its own rows and subtracts its updates from the top rows.
        for (i, xi) in x.iter_mut().enumerate() {
            *xi = match self.owner[i] {
                0 => a[i],
                1 => b[i],
                _ => *xi - ((*xi - a[i]) + (*xi - b[i])),
            };
        }
        self.lower_nodes(values, self.top.iter().copied(), x);
    }

    /// x ← L⁻ᵀx (x in the factor's order).
    fn upper_solve(&self, values: &[f32], x: &mut [f32]) {
        self.upper_nodes(values, self.top.iter().rev().copied(), x);
        let [a, b] = self.on_both_groups(x, |nodes, y| self.upper_nodes(values, nodes.iter().rev().copied(), y));
        for (i, xi) in x.iter_mut().enumerate() {
            match self.owner[i] {
                0 => *xi = a[i],
                1 => *xi = b[i],
                _ => {}
            }
        }
    }

    /// Forward substitution through `nodes`, with AVX2 and FMA where the processor has
    /// them (as faer's kernels do). `upper_nodes` repeats this dispatch: one generic over
    /// the per-node step left the step outside the AVX2 function (no ymm instruction in
    /// its code), so each keeps its own.
    fn lower_nodes(&self, values: &[f32], nodes: impl Iterator<Item = u32>, x: &mut [f32]) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
            #[target_feature(enable = "avx2,fma")]
            fn wide(plan: &SupernodalPlan, values: &[f32], nodes: impl Iterator<Item = u32>, x: &mut [f32]) {
                let mut work = Vec::new();
                nodes.for_each(|k| plan.lower_node(values, k, x, &mut work));
            }
            // SAFETY: the processor has the features `wide` is compiled for.
            return unsafe { wide(self, values, nodes, x) };
        }
        let mut work = Vec::new();
        nodes.for_each(|k| self.lower_node(values, k, x, &mut work));
    }

    /// Back substitution through `nodes`, as `lower_nodes`.
    fn upper_nodes(&self, values: &[f32], nodes: impl Iterator<Item = u32>, x: &mut [f32]) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
            #[target_feature(enable = "avx2,fma")]
            fn wide(plan: &SupernodalPlan, values: &[f32], nodes: impl Iterator<Item = u32>, x: &mut [f32]) {
                let mut work = Vec::new();
                nodes.for_each(|k| plan.upper_node(values, k, x, &mut work));
            }
            // SAFETY: the processor has the features `wide` is compiled for.
            return unsafe { wide(self, values, nodes, x) };
        }
        let mut work = Vec::new();
        nodes.for_each(|k| self.upper_node(values, k, x, &mut work));
    }

    /// The block of supernode k and its rows below the diagonal block.
    #[inline(always)]
    fn node<'a>(&'a self, values: &'a [f32], k: u32) -> (Supernode, &'a [f32], &'a [u32]) {
        let n = self.nodes[k as usize];
        let rows = (n.size + n.pattern_len) as usize;
        let block = &values[n.values..n.values + rows * n.size as usize];
        (n, block, &self.rows[n.pattern_start as usize..(n.pattern_start + n.pattern_len) as usize])
    }

    /// Forward substitution through supernode k: w = [x_top; 0], then column by column
    /// w_j /= L_jj and w_{j+1..} −= L_{j+1..,j} w_j; x_top = w_top and the rows below
    /// take the rest.
    #[inline(always)]
    fn lower_node(&self, values: &[f32], k: u32, x: &mut [f32], w: &mut Vec<f32>) {
        let (n, block, pattern) = self.node(values, k);
        let (start, size) = (n.start as usize, n.size as usize);
        let rows = size + pattern.len();
        w.clear();
        w.extend_from_slice(&x[start..start + size]);
        w.resize(rows, 0.0);
        for j in 0..size {
            let column = &block[j * rows..(j + 1) * rows];
            let wj = w[j] / column[j];
            w[j] = wj;
            axpy(-wj, &column[j + 1..], &mut w[j + 1..]);
        }
        x[start..start + size].copy_from_slice(&w[..size]);
        for (&r, &u) in pattern.iter().zip(&w[size..]) {
            x[r as usize] += u;
        }
    }

    /// Back substitution through supernode k: w = [x_top; x(pattern)], then from the last
    /// column back, w_j = (w_j − L_{j+1..,j}·w_{j+1..}) / L_jj.
    #[inline(always)]
    fn upper_node(&self, values: &[f32], k: u32, x: &mut [f32], w: &mut Vec<f32>) {
        let (n, block, pattern) = self.node(values, k);
        let (start, size) = (n.start as usize, n.size as usize);
        let rows = size + pattern.len();
        w.clear();
        w.extend_from_slice(&x[start..start + size]);
        w.extend(pattern.iter().map(|&r| x[r as usize]));
        for j in (0..size).rev() {
            let column = &block[j * rows..(j + 1) * rows];
            w[j] = (w[j] - dot(&column[j + 1..], &w[j + 1..])) / column[j];
        }
        x[start..start + size].copy_from_slice(&w[..size]);
    }
}

/// L's entries, shared by the threads that factor disjoint groups of its supernodes.
struct SharedFactor(*mut f32);

// SAFETY: the threads write disjoint supernode blocks (see `SupernodalPlan::factor`).
unsafe impl Sync for SharedFactor {}

/// A thread's work space while it factors supernodes.
struct NodeScratch {
    /// Position of a row among the current supernode's rows (u32::MAX: not among them).
    local: Vec<u32>,
    /// One update's product, and where its rows go.
    product: Vec<f32>,
    positions: Vec<usize>,
    /// faer's work space for the dense factorisation of a diagonal block.
    stack: faer::dyn_stack::MemBuffer,
}

impl NodeScratch {
    /// For a factor of `dimension` columns whose largest supernode has `largest`.
    fn new(dimension: usize, largest: usize) -> Self {
        let stack = faer::linalg::cholesky::llt::factor::cholesky_in_place_scratch::<f32>(largest, faer::Par::Seq, Default::default());
        Self { local: vec![u32::MAX; dimension], product: Vec::new(), positions: Vec::new(), stack: faer::dyn_stack::MemBuffer::new(stack) }
    }
}

/// y += a·x.
#[inline(always)]
fn axpy(a: f32, x: &[f32], y: &mut [f32]) {
    for (yi, xi) in y.iter_mut().zip(x) {
        *yi += a * xi;
    }
}

/// x·y in LANES interleaved partial sums: floating-point addition is not associative, so
/// the compiler keeps a single running sum in order unless the code asks for lanes (two
/// AVX registers, so that one sum's latency does not hold up the next).
#[inline(always)]
fn dot(x: &[f32], y: &[f32]) -> f32 {
    const LANES: usize = 16;
    let mut lanes = [0.0f32; LANES];
    let (xc, yc) = (x.chunks_exact(LANES), y.chunks_exact(LANES));
    let tail: f32 = xc.remainder().iter().zip(yc.remainder()).map(|(a, b)| a * b).sum();
    for (a, b) in xc.zip(yc) {
        for l in 0..LANES {
            lanes[l] += a[l] * b[l];
        }
    }
    lanes.iter().sum::<f32>() + tail
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::sparse::linalg::cholesky::{LltRef, factorize_symbolic_cholesky};
    use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
    use faer::{Conj, MatMut, Par, Side};

    /// The lower triangle of a 5-point Laplacian on a g × g grid plus `shift` on the
    /// diagonal, column by column.
    fn grid(g: usize, shift: f64) -> (Vec<u32>, Vec<u32>, Vec<f32>) {
        let (mut col_ptr, mut row_idx, mut values) = (vec![0u32], Vec::new(), Vec::new());
        for c in 0..g * g {
            let (i, j) = (c / g, c % g);
            row_idx.push(c as u32);
            values.push((4.0 + shift) as f32);
            if j + 1 < g {
                row_idx.push((c + 1) as u32);
                values.push(-1.0);
            }
            if i + 1 < g {
                row_idx.push((c + g) as u32);
                values.push(-1.0);
            }
            col_ptr.push(row_idx.len() as u32);
        }
        (col_ptr, row_idx, values)
    }

    /// A shifted grid Laplacian, its symbolic factor and faer's numeric factor.
    struct Factored {
        col_ptr: Vec<u32>,
        row_idx: Vec<u32>,
        values: Vec<f32>,
        symbolic: SymbolicCholesky<u32>,
        factor: Vec<f32>,
    }

    fn factored_grid(g: usize) -> Factored {
        let n = g * g;
        let (col_ptr, row_idx, values) = grid(g, 0.01);
        let pattern = SymbolicSparseColMatRef::new_checked(n, n, &col_ptr, None, &row_idx);
        let symbolic = factorize_symbolic_cholesky(pattern, Side::Lower, Default::default(), Default::default()).unwrap();
        let mut factor = vec![0.0f32; symbolic.len_val()];
        let mut buffer = MemBuffer::new(symbolic.factorize_numeric_llt_scratch::<f32>(Par::Seq, Default::default()));
        symbolic
            .factorize_numeric_llt::<f32>(&mut factor, SparseColMatRef::new(pattern, &values), Side::Lower, Default::default(), Par::Seq, MemStack::new(&mut buffer), Default::default())
            .unwrap();
        Factored { col_ptr, row_idx, values, symbolic, factor }
    }

    /// The solve agrees with faer's on the same factor, and A x reproduces b.
    #[test]
    fn two_group_solve_matches_faers_solve() {
        for g in [3usize, 150, 200] {
            let n = g * g;
            let Factored { col_ptr, row_idx, values, symbolic, factor } = factored_grid(g);
            let b: Vec<f32> = (0..n).map(|i| ((i * 7919) % 13) as f32 - 6.0).collect();
            let mut expected = b.clone();
            let mut buffer = MemBuffer::new(symbolic.solve_in_place_scratch::<f32>(1, Par::Seq));
            LltRef::<'_, u32, f32>::new(&symbolic, &factor).solve_in_place_with_conj(Conj::No, MatMut::from_column_major_slice_mut(&mut expected, n, 1), Par::Seq, MemStack::new(&mut buffer));
            let Some(plan) = SupernodalPlan::new(&symbolic) else {
                // faer picks a simplicial factor for small or very sparse matrices.
                assert!(g < 150, "a {n}-unknown grid should get a supernodal factor");
                continue;
            };
            let (top, imbalance) = plan.split();
            assert!(top + imbalance < 0.5, "top share {top}, imbalance {imbalance}: two threads would gain little");
            let mut x = vec![0.0f32; n];
            plan.solve(&factor, |i| b[i], |i, v| x[i] = v);
            let scale = expected.iter().fold(0.0f32, |m, v| m.max(v.abs()));
            for i in 0..n {
                assert!((x[i] - expected[i]).abs() <= 1e-4 * scale, "row {i}: {} against faer's {}", x[i], expected[i]);
            }
            // Residual of the original matrix, in double precision.
            let mut ax = vec![0.0f64; n];
            for c in 0..n {
                for k in col_ptr[c] as usize..col_ptr[c + 1] as usize {
                    let r = row_idx[k] as usize;
                    let v = values[k] as f64;
                    ax[r] += v * x[c] as f64;
                    if r != c {
                        ax[c] += v * x[r] as f64;
                    }
                }
            }
            let residual = ax.iter().zip(&b).map(|(a, b)| (a - *b as f64).powi(2)).sum::<f64>().sqrt();
            let norm = b.iter().map(|v| (*v as f64).powi(2)).sum::<f64>().sqrt();
            assert!(residual < 1e-3 * norm, "residual {residual} of {norm}");
        }
    }

    /// The two-group factorisation gives faer's factor, on one thread and on two.
    #[test]
    fn two_group_factor_matches_faers_factor() {
        let n = 150 * 150;
        let Factored { col_ptr, row_idx, values, symbolic, factor: expected } = factored_grid(150);
        let mut plan = SupernodalPlan::new(&symbolic).expect("supernodal");
        plan.parallel_entries = 0;
        let destinations = plan.destinations(&col_ptr, &row_idx);
        let factor_on = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let mut l = vec![0.0f32; symbolic.len_val()];
            assert!(pool.install(|| plan.factor(&values, &destinations, &mut l)), "positive definite");
            l
        };
        let (one, two) = (factor_on(1), factor_on(2));
        assert_eq!(one, two);
        let scale = expected.iter().fold(0.0f32, |m, v| m.max(v.abs()));
        for (k, (a, b)) in one.iter().zip(&expected).enumerate() {
            assert!((a - b).abs() <= 1e-5 * scale, "entry {k}: {a} against faer's {b}");
        }
        // An indefinite matrix is refused.
        let mut indefinite = values.clone();
        indefinite[col_ptr[n / 2] as usize] = -1.0;
        let mut l = vec![0.0f32; symbolic.len_val()];
        assert!(!plan.factor(&indefinite, &destinations, &mut l));
    }

    /// The result does not depend on the number of threads.
    #[test]
    fn same_result_on_one_and_two_threads() {
        let n = 150 * 150;
        let Factored { symbolic, factor, .. } = factored_grid(150);
        let mut plan = SupernodalPlan::new(&symbolic).expect("supernodal");
        plan.parallel_entries = 0;
        let b: Vec<f32> = (0..n).map(|i| ((i * 31) % 17) as f32 - 8.0).collect();
        let solve_on = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let mut x = vec![0.0f32; n];
            pool.install(|| plan.solve(&factor, |i| b[i], |i, v| x[i] = v));
            x
        };
        assert_eq!(solve_on(1), solve_on(2));
    }
}
