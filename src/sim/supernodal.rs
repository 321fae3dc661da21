//! Triangular solves with faer's supernodal Cholesky factor on two threads.
//!
//! faer's own solve walks the supernodes one after another. On the fine drapes it is what
//! the run waits for (a solve with the factor of the 20 463-triangle drape reads its 45 MB
//! twice, about 9 ms, and a Newton iteration takes several), and faer's rayon mode, which
//! parallelises the dense work inside each supernode, was slower on these small supernodes
//! (see `direct::PARALLELISM`). Here the elimination tree is cut instead: two groups of
//! disjoint subtrees of about equal size are solved at once, one per thread, and the few
//! supernodes above them (the last separators) after them (forward) or before them
//! (backward). The kernels are written out, column by column over each supernode's dense
//! trapezoid, so that both threads run the same code as one thread does: the result is the
//! same whatever the number of threads.

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
pub struct SolvePlan {
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
}

/// The owner of a row in no group.
const TOP: u8 = 2;

/// The groups may differ by this share of the factor's entries.
const BALANCE: f64 = 0.04;

/// Below this many entries of L a solve takes about a millisecond or less, and the two
/// groups run on the calling thread (the same arithmetic, so the same result).
const PARALLEL_ENTRIES: usize = 1 << 20;

impl SolvePlan {
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
        // Split the largest subtree (its root goes on top) until the subtrees can be dealt
        // to two groups within BALANCE of each other.
        let mut candidates = roots;
        let mut top = Vec::new();
        let assignment = loop {
            candidates.sort_by_key(|&k| std::cmp::Reverse(subtree[k as usize]));
            let mut load = [0usize; 2];
            let mut assignment = [Vec::new(), Vec::new()];
            for &k in &candidates {
                let g = if load[0] <= load[1] { 0 } else { 1 };
                load[g] += subtree[k as usize];
                assignment[g].push(k);
            }
            let balanced = load[0].abs_diff(load[1]) as f64 <= BALANCE * total as f64;
            if balanced || candidates.is_empty() {
                break assignment;
            }
            let largest = candidates.remove(0);
            top.push(largest);
            candidates.extend_from_slice(&children[largest as usize]);
        };
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
        Some(Self { groups: [members(0), members(1)], top: members(TOP), nodes, rows, forward, owner, len: s.len_val(), parallel_entries: PARALLEL_ENTRIES })
    }

    /// Share of L's entries in the supernodes above the two groups, and the difference
    /// between the groups', of the whole.
    pub fn split(&self) -> (f64, f64) {
        let entries = |list: &[u32]| -> usize { list.iter().map(|&k| self.node_entries(k)).sum() };
        let total = self.len.max(1) as f64;
        let (a, b) = (entries(&self.groups[0]), entries(&self.groups[1]));
        (entries(&self.top) as f64 / total, a.abs_diff(b) as f64 / total)
    }

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
    /// them (as faer's kernels do).
    fn lower_nodes(&self, values: &[f32], nodes: impl Iterator<Item = u32>, x: &mut [f32]) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
            #[target_feature(enable = "avx2,fma")]
            fn wide(plan: &SolvePlan, values: &[f32], nodes: impl Iterator<Item = u32>, x: &mut [f32]) {
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
            fn wide(plan: &SolvePlan, values: &[f32], nodes: impl Iterator<Item = u32>, x: &mut [f32]) {
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

    /// The solve agrees with faer's on the same factor, and A x reproduces b.
    #[test]
    fn two_group_solve_matches_faers_solve() {
        for g in [3usize, 150, 200] {
            let n = g * g;
            let (col_ptr, row_idx, values) = grid(g, 0.01);
            let pattern = SymbolicSparseColMatRef::new_checked(n, n, &col_ptr, None, &row_idx);
            let symbolic = factorize_symbolic_cholesky(pattern, Side::Lower, Default::default(), Default::default()).unwrap();
            let mut factor = vec![0.0f32; symbolic.len_val()];
            let mut buffer = MemBuffer::new(symbolic.factorize_numeric_llt_scratch::<f32>(Par::Seq, Default::default()));
            let matrix = SparseColMatRef::new(pattern, &values);
            symbolic
                .factorize_numeric_llt::<f32>(&mut factor, matrix, Side::Lower, Default::default(), Par::Seq, MemStack::new(&mut buffer), Default::default())
                .unwrap();
            let b: Vec<f32> = (0..n).map(|i| ((i * 7919) % 13) as f32 - 6.0).collect();
            let mut expected = b.clone();
            let mut buffer = MemBuffer::new(symbolic.solve_in_place_scratch::<f32>(1, Par::Seq));
            LltRef::<'_, u32, f32>::new(&symbolic, &factor).solve_in_place_with_conj(Conj::No, MatMut::from_column_major_slice_mut(&mut expected, n, 1), Par::Seq, MemStack::new(&mut buffer));
            let Some(plan) = SolvePlan::new(&symbolic) else {
                // faer picks a simplicial factor for small or very sparse matrices.
                assert!(g < 150, "a {n}-unknown grid should get a supernodal factor");
                continue;
            };
            let (top, imbalance) = plan.split();
            assert!(imbalance <= BALANCE + 1e-12 || plan.groups[1].is_empty(), "imbalance {imbalance}");
            assert!(top < 0.5, "top share {top}");
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

    /// The result does not depend on the number of threads.
    #[test]
    fn same_result_on_one_and_two_threads() {
        let g = 150;
        let n = g * g;
        let (col_ptr, row_idx, values) = grid(g, 0.01);
        let pattern = SymbolicSparseColMatRef::new_checked(n, n, &col_ptr, None, &row_idx);
        let symbolic = factorize_symbolic_cholesky(pattern, Side::Lower, Default::default(), Default::default()).unwrap();
        let mut factor = vec![0.0f32; symbolic.len_val()];
        let mut buffer = MemBuffer::new(symbolic.factorize_numeric_llt_scratch::<f32>(Par::Seq, Default::default()));
        symbolic
            .factorize_numeric_llt::<f32>(&mut factor, SparseColMatRef::new(pattern, &values), Side::Lower, Default::default(), Par::Seq, MemStack::new(&mut buffer), Default::default())
            .unwrap();
        let mut plan = SolvePlan::new(&symbolic).expect("supernodal");
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
